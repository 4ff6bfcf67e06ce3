"""The study's chunked store (zarr): finished grid blocks and finished cases, written as they arrive, read back by a
rerun so that nothing finished is computed twice.

Layout of ``<out>/<name>.zarr`` (zarr format 2, which every zarr reader opens; format 3 has no specification yet for
the fixed-width strings that some results hold):

* the grid variables of a stepped study, with the grid's full dimensions (``solution``, ``restitution``,
  ``clearance``, ``bumper_frequency``, ``sweep``, ``frequency``, and ``stop`` where a variable has one), chunked like
  the grid's blocks, ``block_checksum`` (the SHA-256 of the values each block wrote) and ``block_done`` (one flag per
  block, set after every variable of the block and its checksum are written, so a block cut off half-way is computed
  again);
* the group ``cases``: one array per finished case (``<engine>-<key>``), its result fields packed in one ``.npz``
  byte stream (no pickle; one write per case, not one per field: a design study's cases are stored 12x faster), its
  attribute ``checksum`` the digest of the values;
* the attributes ``fingerprint`` (the scene's values, the package version and its source), ``code``,
  ``scene_values`` (the values text the fingerprint is made of) and ``scene_path``: a store of changed values (the
  keys named) or other code is started afresh rather than mixed, saying why and how much it discards; a store whose
  fingerprint is not that of its own recorded values and code was edited or damaged, and is set aside (never
  deleted); a store begun by another scene file is refused, never deleted.

A store proves what it serves: every finished block is checked against its checksum when a run resumes and again
before its values are exported, and every case when it is read; one that fails (a lost, truncated or swapped chunk,
lost metadata) is computed again and the run says how many in one line. No fill value passes as a result: every
point belongs to a block, and the export waits until every block has proved itself.

Only the process that runs the study writes the store (workers return their results to it), so a cluster needs no
shared file system. :func:`vibroimpact.runs.output_files.claim_output` keeps a second study off the same output.
"""

from __future__ import annotations

import asyncio
import io
import json
import os
import shutil
import warnings
from pathlib import Path
from typing import Any, Callable

import numpy as np
import xarray as xr
import zarr
from numpy.typing import NDArray
from zarr.core.sync import sync  # zarr's own event loop, the one its synchronous API runs on

from vibroimpact.runs.fingerprints import NOT_IN_FINGERPRINT, case_key, changed_keys, code_fingerprint, fingerprint_of, source_hash, store_fingerprint, values_digest
from vibroimpact.runs.store_record import add_to_ledger, consolidated_damage, count_cases, finished_work, forget_ledger, ledger_names, read_record, record_digest, restore, set_aside, check_members_readable

__all__ = ["source_hash", "case_key", "StudyStore", "store_fingerprint", "code_fingerprint", "values_digest", "StoreOfAnotherScene", "StoreUnusable", "NOT_IN_FINGERPRINT", "ZARR_FORMAT"]


ZARR_FORMAT = 2
_CASES = "cases"
_BLOCK_DONE = "block_done"
#: One SHA-256 per block (32 bytes) of the values it wrote, set before its ``block_done`` flag.
_BLOCK_CHECKSUM = "block_checksum"
#: The grid's variables, recorded when the grid begins (a variable whose metadata is lost is missed by name).
_GRID_VARIABLES = "grid_variables"
#: The copy of the grid's metadata files and its digest (:mod:`vibroimpact.runs.store_record`), written last.
_GRID_RECORD = "grid_record"
_GRID_RECORD_DIGEST = "grid_record_sha256"
#: The root's attribute set when a store is kept whole with its consolidated metadata (:meth:`StudyStore.keep`).
_KEPT = "kept_with_consolidated_metadata"
#: The root's attributes that lay the grid out, kept in the record.
_GRID_PLAN = ("grid_shape", "block_shape", _GRID_VARIABLES)


#: Attributes whose values must keep the variable's own type (CF: flag_values of an int8 flag are int8).
_TYPED_ATTRIBUTES = ("flag_values", "flag_masks", "valid_min", "valid_max", "valid_range")


class StoreUnusable(RuntimeError):
    """The store cannot be read for a reason no rebuilding mends (an unreadable array beside the grid's): the caller
    sets it aside (:meth:`StudyStore.start_afresh`) and computes again."""


class StoreOfAnotherScene(RuntimeError):
    """The output folder's store holds the finished work of another scene file (a name clash): it is not deleted."""


class StudyStore:
    """A zarr store of a study's finished work (module docstring); ``path=None`` keeps it in memory.

    Parameters
    ----------
    path : Path or None
        The store's folder (``<out>/<name>.zarr``), or None for an in-memory store (a study run from Python).
    fingerprint : str
        :func:`store_fingerprint` of the scene; a folder holding another fingerprint is emptied first, and ``say``
        is told why and how much finished work that discards.
    scene_path : Path or None
        The scene file the work comes from (recorded; a store begun by another scene file is refused, not emptied).
    say : callable or None
        Receives one line whenever finished work is discarded (a changed scene or code, damaged blocks or cases).
    values : str
        :func:`~vibroimpact.runs.fingerprints.fingerprinted_values` of the scene, recorded beside the fingerprint: a
        rerun of changed values names the keys that changed, and a fingerprint that is not its own values' is told
        apart as edited or damaged. ``""``: not recorded (the reasons are then said without the keys).

    Raises
    ------
    StoreOfAnotherScene
        When ``path`` holds the store of another scene file (same name, other file): nothing is deleted.
    """

    def __init__(self, path: Path | None, fingerprint: str, scene_path: Path | None = None, say: Callable[[str], None] | None = None, values: str = "") -> None:
        self.path = path
        self.fingerprint = fingerprint
        self.values = values
        self.say = say or (lambda _line: None)
        #: Cases read back whose values failed their checksum (computed again).
        self.damaged_cases = 0
        #: Cases found without their checksum: cut off before it was written, or it was lost (computed again).
        self.unsealed_cases = 0
        #: Cases the store had finished (:data:`~vibroimpact.runs.store_record.LEDGER`) that are gone from it.
        self.lost_cases = 0
        self.store: Any = str(path) if path is not None else zarr.storage.MemoryStore()
        source = str(Path(scene_path).resolve()) if scene_path is not None else ""
        self.scene_path = source
        if path is not None and path.exists():
            for partial in (*path.glob("*.partial"), *path.glob("*/*.partial")):  # zarr's half-written files of a kill: never data
                partial.unlink(missing_ok=True)
            self._discard_unless_ours(path, source)
        #: Whether this run began the store (nothing of an earlier run in it): only such a store may be removed unasked.
        self.fresh = path is None or not path.exists()
        if path is not None and self.fresh:
            forget_ledger(path)  # of a store removed by hand
        self._ledger = ledger_names(path) if path is not None else set()
        # the run reads every array's own metadata, as the export does: a kept store's consolidated copy
        # (:meth:`keep`) could vouch for an array whose own files are lost or edited
        self.root = zarr.open_group(self.store, mode="a", zarr_format=ZARR_FORMAT, use_consolidated=False)
        if "fingerprint" not in self.root.attrs:
            self.root.attrs.update(self._identity())
        self._grid_ready = _BLOCK_DONE in self.root or any(key in self.root.attrs for key in (_GRID_VARIABLES, _GRID_RECORD))
        if path is not None and self.root.attrs.get(_KEPT):
            self._check_consolidated(path)
        self._arrays: dict[str, Any] = {}
        self._cases_group: Any = None

    def start_afresh(self, why: str) -> None:
        """Set the store aside (renamed, never deleted; one line says where and why) and begin an empty one."""
        if self.path is None:
            raise StoreUnusable(why)  # a store in memory is never damaged: this is a bug, said as it is
        aside = set_aside(self.path)
        self.say(f"{self.path}: cannot be read ({why}): set aside as {aside.name}, computed again")
        self.root = zarr.open_group(self.store, mode="a", zarr_format=ZARR_FORMAT, use_consolidated=False)
        self.root.attrs.update(self._identity())
        self._arrays.clear()
        self._cases_group = None
        self._grid_ready = False
        forget_ledger(self.path)
        self._ledger = set()

    def _discard_unless_ours(self, path: Path, source: str) -> None:
        """Empty the folder ``path`` unless it holds this scene's store; say why and how much was discarded."""
        try:
            attrs: dict[str, Any] | None = dict(zarr.open_group(str(path), mode="r", zarr_format=ZARR_FORMAT, use_consolidated=False).attrs)
        except Exception:  # noqa: BLE001 - unreadable or damaged root metadata (a JSON error, a missing file)
            attrs = None
        if attrs is not None and attrs.get("fingerprint") == self.fingerprint:
            return
        if attrs is not None and source and attrs.get("scene_path") and attrs["scene_path"] != source:
            raise StoreOfAnotherScene(
                f"{path} holds the finished work of another scene ({attrs['scene_path']}); it is kept: remove it, or "
                "run this scene with another --out (or another name)")
        recorded = attrs.get("scene_values") if attrs is not None else None
        damage = None
        if attrs is None or "fingerprint" not in attrs:
            damage = f"its attributes are {'unreadable' if attrs is None else 'lost'} (damaged)"
        elif isinstance(recorded, str) and fingerprint_of(str(attrs.get("code")), recorded) != attrs["fingerprint"]:
            damage = "its fingerprint is not that of the scene values and code it recorded (edited or damaged)"
        if damage is not None:  # kept for whoever wants to look, never deleted
            work = finished_work(path, _BLOCK_DONE, _CASES, ZARR_FORMAT)
            aside = set_aside(path)
            self.say(f"{path}: {damage}: set aside as {aside.name} ({work}), computed again")
            return
        if attrs.get("code") != code_fingerprint():
            why = "the package's code changed"
        else:
            keys = changed_keys(recorded, self.values) if isinstance(recorded, str) and self.values else ""
            why = f"the scene's values changed ({keys})" if keys else "the scene's values changed"
        self.say(f"{path}: {why} since it was written: {finished_work(path, _BLOCK_DONE, _CASES, ZARR_FORMAT)} discarded, computed again")
        self.remove()  # renamed first: a removal cut off half-way leaves no store that looks damaged

    def _identity(self) -> dict[str, str]:
        """The root attributes that say whose store it is: the fingerprint, the code, the values (if known) and the
        scene file."""
        identity = {"fingerprint": self.fingerprint, "code": code_fingerprint(), "scene_path": self.scene_path}
        return identity | ({"scene_values": self.values} if self.values else {})

    # -- cases -------------------------------------------------------------------------------------------------

    def load_case(self, name: str, fields: tuple[str, ...]) -> dict[str, NDArray[np.generic]] | None:
        """The stored result of the case called ``name``, or None if it is not (completely) stored."""
        try:
            cases = self._cases()
            if name not in cases:
                self.lost_cases += name in self._ledger  # finished once, gone since; else never computed
                return None
            node = cases[name]
            checksum = node.attrs.get("checksum")
        except Exception:  # noqa: BLE001 - damaged metadata (a truncated .zarray or .zattrs): computed again
            self.damaged_cases += 1
            return None
        if not isinstance(node, zarr.Array) or not checksum:  # written by older code, or cut off before its checksum
            self.unsealed_cases += 1
            return None
        try:
            with np.load(io.BytesIO(np.asarray(node[...], dtype=np.uint8).tobytes()), allow_pickle=False) as packed:
                result: dict[str, NDArray[np.generic]] | None = {field: packed[field] for field in packed.files}
        except Exception:  # noqa: BLE001 - a lost chunk reads as zeros, a damaged one raises whatever its codec raises
            result = None
        if result is None or values_digest(sorted(result.items())).hex() != checksum:
            self.damaged_cases += 1  # computed again; the run says how many
            return None
        if not set(fields) <= set(result):
            return None  # written by older code: run again
        return {field: result[field] for field in fields}

    def save_case(self, name: str, result: dict[str, NDArray[np.generic]]) -> None:
        """Store a finished case's result: its fields packed in one array whose checksum attribute proves them."""
        written = {}
        for field, value in result.items():
            array = np.asarray(value)
            written[field] = array.astype(str) if array.dtype == object else array  # text (notes, names): fixed-width strings
        buffer = io.BytesIO()
        np.savez(buffer, **written)
        packed = np.frombuffer(buffer.getvalue(), dtype=np.uint8)
        cases = self._cases()
        try:
            array = cases.create_array(name, shape=packed.shape, dtype=np.uint8, chunks=packed.shape, overwrite=True)
        except Exception:  # noqa: BLE001 - the case's old metadata is unreadable (truncated): its folder goes whole
            if self.path is None:
                raise
            shutil.rmtree(self.path / _CASES / name, ignore_errors=True)
            array = cases.create_array(name, shape=packed.shape, dtype=np.uint8, chunks=packed.shape, overwrite=True)
        array[...] = packed
        array.attrs["checksum"] = values_digest(sorted(written.items())).hex()  # a case cut off before it is not stored
        if self.path is not None:
            add_to_ledger(self.path, name)

    def case_count(self) -> int:
        """Finished cases in the store."""
        if self.path is None:
            return count_cases(self._cases())
        count = 0  # read file by file: a case whose metadata is damaged is not finished, and hides no other
        for attributes in sorted((self.path / _CASES).glob("*/.zattrs")):
            try:
                count += bool(json.loads(attributes.read_text()).get("checksum"))
            except (OSError, ValueError, AttributeError):
                pass
        return count

    def _cases(self) -> Any:
        """The group of finished cases; on disk, its own metadata (nothing but the format) rewritten where it is lost
        or unreadable, and a file where its folder should be set aside with the whole store."""
        if self._cases_group is not None:
            return self._cases_group
        if self.path is not None:
            folder = self.path / _CASES
            if folder.exists() and not folder.is_dir():
                self.start_afresh(f"{folder.name} is not a folder")
            elif folder.is_dir():
                try:
                    readable = json.loads((folder / ".zgroup").read_text()).get("zarr_format") == ZARR_FORMAT
                    json.loads((folder / ".zattrs").read_text()) if (folder / ".zattrs").exists() else None
                except (OSError, ValueError, AttributeError):
                    readable = False
                if not readable:
                    (folder / ".zattrs").unlink(missing_ok=True)
                    (folder / ".zgroup").write_text(json.dumps({"zarr_format": ZARR_FORMAT}))
                    self.say(f"{folder}: its metadata was lost or unreadable: rebuilt")
        self._cases_group = self.root.require_group(_CASES)
        return self._cases_group

    # -- grid blocks -------------------------------------------------------------------------------------------

    @property
    def grid_ready(self) -> bool:
        """Whether the grid's variables exist (the first finished block creates them)."""
        return self._grid_ready

    def begin_grid(self, template: xr.Dataset, block_count: int, plan: tuple[tuple[int, ...], tuple[int, ...]]) -> None:
        """Create the grid's variables from ``template`` (lazy arrays with the grid's dimensions and chunks; nothing
        is computed) and ``block_done``; ``plan`` (the grid's shape and a block's) is kept for a resumed run."""
        # the bookkeeping first, the grid's variables and their list last: a kill in between leaves a store whose
        # grid a rerun drops (no variables listed, or flags without variables), never variables without flags
        checksum = self.root.create_array(_BLOCK_CHECKSUM, shape=(block_count, 32), chunks=(1, 32), dtype="uint8", fill_value=0, overwrite=True)
        checksum.attrs["_ARRAY_DIMENSIONS"] = ["block", "sha256_byte"]
        done = self.root.create_array(_BLOCK_DONE, shape=(block_count,), chunks=(1,), dtype="uint8", fill_value=0, overwrite=True)
        done.attrs["_ARRAY_DIMENSIONS"] = ["block"]
        encoding = {name: {"_FillValue": None} for name, variable in template.data_vars.items() if variable.dtype.kind in "iub"}
        # the dataset's attributes become the group's: the fingerprint goes with them
        template = template.assign_attrs(dict(self.root.attrs) | {"grid_shape": list(plan[0]), "block_shape": list(plan[1]), _GRID_VARIABLES: sorted(map(str, template.data_vars))})
        template.to_zarr(self.store, mode="a", compute=False, zarr_format=ZARR_FORMAT, encoding=encoding, consolidated=False)
        self.root = zarr.open_group(self.store, mode="a", zarr_format=ZARR_FORMAT, use_consolidated=False)
        if self.path is not None:  # the record of the metadata last: a grid without it was cut off while created
            record = read_record(self.path, [*template.data_vars, _BLOCK_DONE, _BLOCK_CHECKSUM], {key: self.root.attrs[key] for key in _GRID_PLAN})
            self.root.attrs.update({_GRID_RECORD: record, _GRID_RECORD_DIGEST: record_digest(record)})
        self._arrays.clear()
        self._grid_ready = True

    def check_grid(self) -> int:
        """Compare the grid's metadata (every array's ``.zarray`` and ``.zattrs``, the grid's plan) with the record
        written when the grid began and write back what differs, saying which arrays were rebuilt; a grid without a
        whole record (cut off while being created, or its record damaged) is dropped; a store with an unreadable array
        beside the grid's is set aside (:meth:`start_afresh`). Return the finished blocks dropped (0: the grid's
        metadata is as it was written, or rebuilt).

        Call it before :meth:`grid_plan` and :meth:`verify_blocks`: they read the metadata it restores.
        """
        if self.path is None:
            return 0
        dropped = self._check_grid_record() if self._grid_ready else 0
        try:  # an unreadable array beside the grid's fails every read of the store: known before any work
            check_members_readable(self.path, skip=(_CASES,))
        except ValueError as error:
            self.start_afresh(str(error))
        return dropped

    def _check_grid_record(self) -> int:
        """:meth:`check_grid` for the grid's own arrays and plan; return the finished blocks dropped."""
        try:
            attrs = dict(self.root.attrs)
            record = attrs[_GRID_RECORD]
            whole = isinstance(record, dict) and attrs[_GRID_RECORD_DIGEST] == record_digest(record)
        except Exception:  # noqa: BLE001 - no record (cut off before it), or unreadable attributes
            whole = False
        if not whole:
            return self._drop_grid()
        rebuilt = restore(self.path, record)
        if any(attrs.get(key) != value for key, value in record["plan"].items()):
            self.root.attrs.update(record["plan"])
            rebuilt.append("the grid's plan")
        if rebuilt:
            self.root = zarr.open_group(self.store, mode="a", zarr_format=ZARR_FORMAT, use_consolidated=False)
            self._arrays.clear()
            self.say(f"{self.path}: metadata lost or changed since it was written, rebuilt from the store's record: {', '.join(rebuilt)}")
        return 0

    def grid_plan(self) -> tuple[tuple[int, ...], tuple[int, ...]] | None:
        """The grid's shape and a block's, as the run that began the store planned them (None: not recorded)."""
        attrs = self.root.attrs
        if "grid_shape" not in attrs or "block_shape" not in attrs:
            return None
        return tuple(int(n) for n in attrs["grid_shape"]), tuple(int(n) for n in attrs["block_shape"])  # type: ignore[union-attr]

    def finished_blocks(self) -> NDArray[np.bool_]:
        """One flag per block: its results are stored."""
        return np.asarray(self.root[_BLOCK_DONE][...], dtype=bool)

    def write_block(self, index: int, region: dict[str, slice], block: dict[str, tuple[tuple[str, ...], NDArray[np.generic]]]) -> None:
        """Write the variables of block ``index`` (name -> (dimensions, values)) into ``region`` (dimension ->
        slice; unnamed dimensions whole), then flag the block done."""
        writes = []
        written = []
        for name, (dims, values) in sorted(block.items()):
            array = self._array(name)
            typed = values.astype(array.dtype, copy=False)
            writes.append(array.async_array.setitem(tuple(region.get(dim, slice(None)) for dim in dims), typed))
            written.append((name, typed))

        async def write_all() -> None:
            await asyncio.gather(*writes)

        # one round trip to zarr's event loop for every variable of the block (one per variable costs 2.3x as much)
        sync(write_all())
        self._array(_BLOCK_CHECKSUM)[index] = np.frombuffer(values_digest(written), dtype=np.uint8)
        self._array(_BLOCK_DONE)[index] = 1

    def verify_blocks(self, region_of: Callable[[int], dict[str, slice]]) -> int:
        """Check every finished block against the checksum it was written with; a block that fails (a lost, truncated
        or swapped chunk) is flagged unfinished, so that it is computed again. Return how many failed.

        A grid whose metadata is damaged (a variable, ``block_done`` or the checksums missing) is dropped whole: all
        its finished blocks count as failed. ``region_of(index)``: the block's slices (dimension -> slice).
        """
        if not self._grid_ready or self.path is None:  # memory is not damaged on its way to and from a disk
            return 0
        try:
            with warnings.catch_warnings():
                warnings.simplefilter("error")  # zarr warns of an array whose metadata is lost: the grid is damaged
                done = self.finished_blocks()
                names = [str(name) for name in self.root.attrs[_GRID_VARIABLES]]  # type: ignore[union-attr]
                arrays = {name: self._array(name) for name in names}
                checksums = np.asarray(self._array(_BLOCK_CHECKSUM)[...])
        except Exception:  # noqa: BLE001 - missing or unreadable metadata: nothing of the grid can be trusted
            return self._drop_grid()
        damaged = 0
        for index in np.flatnonzero(done):
            region = region_of(int(index))
            try:
                values = [(name, np.asarray(array[tuple(region.get(dim, slice(None)) for dim in array.attrs["_ARRAY_DIMENSIONS"])])) for name, array in arrays.items()]
                good = values_digest(values) == checksums[index].tobytes()
            except Exception:  # noqa: BLE001 - a damaged chunk raises whatever its codec raises (blosc: RuntimeError)
                good = False
            if not good:
                self._array(_BLOCK_DONE)[index] = 0
                damaged += 1
        return damaged

    def _drop_grid(self) -> int:
        """Forget the grid (its arrays deleted, the next finished block begins it again); return its finished blocks."""
        try:
            count = int(self.finished_blocks().sum())
        except Exception:  # noqa: BLE001 - the flags themselves are damaged: count what the plan says
            plan = self.grid_plan()
            count = int(np.prod([-(-n // b) for n, b in zip(*plan)])) if plan is not None else 0
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")  # zarr warns of the array whose metadata is lost: it goes anyway
            names = {str(name) for name in self.root.attrs.get(_GRID_VARIABLES, [])}  # type: ignore[union-attr]
            try:
                names |= set(self.root.array_keys())  # those of a grid cut off before its list was written
            except Exception:  # noqa: BLE001 - an array whose metadata is unreadable: the folders tell
                names |= {member.parent.name for member in self.path.glob("*/.zarray")} if self.path is not None else set()
            names -= {_CASES}
            for name in names:
                if self.path is not None:  # on disk: the folder whole, an array whose metadata is lost has chunk files
                    shutil.rmtree(self.path / name, ignore_errors=True)
                elif name in self.root:
                    del self.root[name]
            self.root = zarr.open_group(self.store, mode="a", zarr_format=ZARR_FORMAT, use_consolidated=False)
        for key in (_GRID_VARIABLES, _GRID_RECORD, _GRID_RECORD_DIGEST):
            self.root.attrs.pop(key, None)
        self._arrays.clear()
        self._grid_ready = False
        return count

    def _array(self, name: str) -> Any:
        """The store's array ``name``, opened once."""
        if name not in self._arrays:
            self._arrays[name] = self.root[name]
        return self._arrays[name]

    def block_count(self) -> int:
        """Finished blocks in the store (0 where its flags cannot be read: :meth:`verify_blocks` then drops the grid)."""
        if not self._grid_ready:
            return 0
        try:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")  # zarr warns of an array whose metadata is lost
                return int(self.finished_blocks().sum())
        except Exception:  # noqa: BLE001 - lost or damaged flags (a kill while the grid was being created)
            return 0

    def grid_dataset(self) -> xr.Dataset:
        """The grid's variables, lazily (dask arrays over the store's chunks), without ``block_done``."""
        names = {str(name) for name in self.root.attrs.get(_GRID_VARIABLES, [])}  # type: ignore[union-attr]
        try:
            if self.path is not None:  # zarr opens every array beside ours at once, and one that fails leaves the rest pending
                check_members_readable(self.path, skip=(_CASES,))
            others = [name for name in self.root.array_keys() if name not in names]  # bookkeeping, kept coordinates, anything foreign: never exported
            dataset = xr.open_zarr(self.store, consolidated=False, zarr_format=ZARR_FORMAT, drop_variables=others)
        except Exception as error:  # noqa: BLE001 - whatever an unreadable array raises (a JSON error, a missing file)
            raise StoreUnusable(f"{type(error).__name__}: {error}") from error
        dataset.attrs.clear()  # the fingerprint, and a kept store's attributes of its last run: the study sets its own
        for variable in dataset.variables.values():
            for key in _TYPED_ATTRIBUTES:
                if key in variable.attrs and isinstance(variable.attrs[key], list):
                    variable.attrs[key] = np.asarray(variable.attrs[key], dtype=variable.dtype)
        return dataset

    def keep(self, dataset: xr.Dataset) -> None:
        """Finish a store that outlives its study: the coordinates of its dimensions (``frequency``, the swept
        parameters, ``solution``) and the attributes of the study's ``dataset``, and consolidated metadata, so that
        ``xarray.open_zarr(path)`` opens a labelled dataset at once."""
        sizes: dict[str, int] = {}
        for _name, array in self.root.arrays():
            sizes.update(zip(array.attrs.get("_ARRAY_DIMENSIONS", ()), array.shape))
        coords = {}
        for dim, size in sizes.items():
            if dim in dataset.coords and dim not in self.root:
                values = np.atleast_1d(dataset[dim].values)
                if values.size == size:
                    coords[dim] = values.astype(str) if values.dtype == object else values
        if coords:
            xr.Dataset(coords=coords, attrs=dict(self.root.attrs)).to_zarr(self.store, mode="a", zarr_format=ZARR_FORMAT, consolidated=False)  # keeps the group's attributes
            self.root = zarr.open_group(self.store, mode="a", zarr_format=ZARR_FORMAT, use_consolidated=False)
        attrs = dict(dataset.attrs)
        self.root.attrs.update({key: value.tolist() if isinstance(value, np.ndarray) else value.item() if isinstance(value, np.generic) else value for key, value in attrs.items()})
        self.root.attrs[_KEPT] = True  # its consolidated metadata is checked when a run opens it again
        zarr.consolidate_metadata(self.store, zarr_format=ZARR_FORMAT)

    def _check_consolidated(self, path: Path) -> None:
        """Say whether a kept store's consolidated metadata is damaged (:func:`consolidated_damage`; written again
        when the run keeps the store); the store is then no longer marked as kept, so that a run cut off before it
        keeps it again is not taken for damage."""
        damage = consolidated_damage(path)
        if damage is not None:
            self.say(f"{path / '.zmetadata'}: the store's consolidated metadata {damage}: the run reads every array's own, and writes it again when it keeps the store")
        self.root.attrs[_KEPT] = False

    def remove(self) -> None:
        """Delete the store (after its results are exported): renamed first, so that a removal cut off half-way
        never leaves a store whose flags outlive its data."""
        if self.path is not None and self.path.exists():
            doomed = self.path.with_name(f".{self.path.name}.removed-{os.getpid()}")
            os.replace(self.path, doomed)
            forget_ledger(self.path)
            shutil.rmtree(doomed, ignore_errors=True)
