"""Run a scene: its kind of study (:data:`vibroimpact.scene.kinds.KINDS`) expands it into its grid, computes the solutions it
asks for and gathers one labelled ``xarray.Dataset``.

Output contract (read by other tools; keep these names): dimensions ``solution`` (strings), each swept parameter
(``restitution`` [1], ``clearance`` [m]) and ``frequency`` [Hz]; variables ``x1_amplitude`` [m],
``x2_amplitude`` [m], ``force_amplitude`` [N], ``suspension_force_amplitude`` [N], ``impulse`` [N s], ``phase``
[rad] and ``regime`` (CF flags). Unswept stop parameters are scalar coordinates. Swept-sine scenes add dimension
``sweep``: the swept runs' estimates are ``swept_<quantity>`` (sweep, frequency) and their running estimates
``running_<quantity>`` (sweep, elapsed_time); the steady-state solutions are not repeated along ``sweep``. Benchmark
scenes have dimensions (case, engine, rtol). Every dataset begins with the same header (``title``, ``scene_name``,
``scene``, the provenance: :func:`dataset_header`) and names its kind in the attribute ``study_kind``.

In the file (:func:`write_dataset`) each solution lives on the frequencies it was computed at: the root group holds
the solutions computed on every frequency (the closed forms), and a study that simulates puts its simulated solutions
(the time-domain engines, ``solution`` = ``exact``, ``momentary``, ...) in the group ``simulated``, on its own
``frequency`` coordinate (the scene's ``simulation.frequency``), with the same variable names, dimensions, other
coordinates and attributes. A variable that holds no value over a group's solutions is not in that group (``converged``
and ``lyapunov_*`` are only in ``simulated``, ``stable`` and ``phase`` only in the root). The root says where the
simulations are: attribute ``simulated_solutions_group`` and its ``comment``. Read both with ``xarray.open_groups``
(``xarray.open_datatree`` refuses a child whose ``frequency`` differs from its parent's); :func:`read_dataset` joins
them into the one dataset :func:`run_study` returns (every solution on every frequency, NaN or ``not_applicable``
where it was not computed), :func:`split_groups` splits that one. In the file every dimension labelled by strings
(``solution``, ``sweep``, ``case``, ``engine``, ...) or by numbers out of order (a bumper bifurcation's
``bumper_frequency``) is an index dimension and its labels are the auxiliary coordinate ``<dimension>_label`` (CF 1.8
section 6.1.1, :mod:`vibroimpact.runs.labels`); :func:`read_dataset` puts them back on their dimensions.
"""

from __future__ import annotations

import sys
from datetime import datetime, timezone
from pathlib import Path
from typing import Any, Mapping, Protocol, Sequence

import numpy as np
import pandas as pd
import xarray as xr

from vibroimpact import __version__
from vibroimpact.engines.registry import compile_notice, engine_spec
from vibroimpact.model.keywords import suggest_keywords
from vibroimpact.runs.cluster import Progress
from vibroimpact.runs.runner import Runner
from vibroimpact.runs.spawn_main import refuse_in_a_spawned_import
from vibroimpact.orbits.call_progress import quiet_calls
from vibroimpact.runs.estimate import Costs, Estimate
from vibroimpact.runs.labels import decode_labels, encode_labels
from vibroimpact.runs.output_files import atomic_path
from vibroimpact.runs.fingerprints import source_hash
from vibroimpact.runs.store import StudyStore
from vibroimpact.scene.kinds import kind_named
from vibroimpact.scene.schema import ENGINE_SOLUTIONS, Scene

__all__ = ["StudyKind", "study_kind", "batched_engines", "run_study", "prepare_engines", "atomic_path", "write_dataset", "read_dataset", "split_groups", "join_groups", "absent_value", "SIMULATED_GROUP", "netcdf_attribute", "provenance", "dataset_header", "HEADER_ATTRIBUTES"]

class StudyKind(Protocol):
    """What a kind of study does with a scene (each kind's ``study.py``, registered in :data:`vibroimpact.scene.kinds.KINDS`)."""

    @property
    def name(self) -> str:
        """The kind's name, as :attr:`Scene.kind` says it and datasets record it (``study_kind``)."""
        ...

    def run(self, scene: Scene, progress: Progress | None, runner: Runner) -> xr.Dataset:
        """The scene's dataset, without the header :func:`run_study` writes (:func:`dataset_header`); ``progress`` receives a line per finished step (None: silence); its work runs in
        ``runner`` (this process, a local dask cluster or a running one), which keeps finished work in its store."""
        ...

    def estimate(self, scene: Scene, jobs: int, costs: Costs) -> Estimate:
        """The predicted wall time and memory of running the scene with ``jobs`` processes, on the calibration machine."""
        ...

    def engines(self, scene: Scene) -> tuple[str, ...]:
        """The registered engines the study runs on the scene (those with compiled kernels are compiled, or loaded, before
        any work starts: :func:`prepare_engines`)."""
        ...


def batched_engines(kind: StudyKind, scene: Scene) -> tuple[str, ...]:
    """Those of the study's engines whose batch entry it runs (many starts in one compiled call: its
    ``batched_engines(scene)``, where the kind has one; none otherwise): only these compile it (~6-10 s each)."""
    named = getattr(kind, "batched_engines", None)
    return tuple(named(scene)) if named is not None else ()


def study_kind(scene: Scene) -> StudyKind:
    """The study of ``scene``'s kind (its module is imported now)."""
    study: StudyKind = kind_named(scene.kind).make_study()
    return study


def prepare_engines(engines: Sequence[str], progress: Progress | None = None, batched: Sequence[str] = ()) -> float:
    """Compile the kernels of the registered ``engines`` in this process, once per machine, before any worker starts;
    return the seconds it took (0 where numba's on-disk cache already holds them, or no engine has kernels).

    numba compiles an engine's kernels on first use and caches them on disk (``@njit(cache=True)``); a cold cache
    costs :data:`~vibroimpact.engines.registry.FIRST_COMPILE_TIME` of compiling per engine. Done here, the workers of a local cluster load the cached code (~0.1 s
    each, before their first task: :class:`~vibroimpact.runs.runner.Runner`) instead of each compiling it again at
    once inside its first point's wall time, and the user is told why the first run waits, in one line, before it does.
    Cached kernels are loaded here too, for the work this process runs itself. The engines named in ``batched`` have
    their batch entry compiled too; the others not (a scene compiles only what it runs).
    An engine is asked whether it has kernels (its capability ``compiled``), never named here.
    """
    import time

    total = 0.0
    for name in dict.fromkeys(engines):
        spec = engine_spec(name)
        batch = name in batched
        if spec.kernels_cached(batch):
            spec.prepare_kernels(batch)  # loaded here too (~0.1 s): work run in this process times none of it
            continue
        if progress is not None:
            progress(compile_notice(name))
        start = time.perf_counter()
        spec.prepare_kernels(batch)
        elapsed = time.perf_counter() - start
        total += elapsed
        if progress is not None:
            progress(f"compiled the {name} engine's kernels in {elapsed:.0f} s")
    return total


def _stderr_progress(message: str) -> None:
    print(message, file=sys.stderr, flush=True)


@suggest_keywords
def run_study(scene: Scene, progress: Progress | None = _stderr_progress, jobs: int = 1, store: StudyStore | None = None, scheduler: str | None = None, load: bool = True) -> xr.Dataset:
    """Compute every solution of ``scene`` over its grid.

    Parameters
    ----------
    scene : Scene
        A validated scene.
    progress : callable, optional
        Receives one line per finished step; ``None`` for silence (also silences the progress bar).
    jobs : int
        Worker processes of the local dask cluster; 1: this process alone.
    store : StudyStore, optional
        Where finished work is kept as it arrives (a rerun skips it); None: in memory.
    scheduler : str, optional
        Address of a running dask scheduler to run the work on instead of a local cluster.
    load : bool
        Load the dataset into memory; False: a stepped study's variables stay lazy arrays over ``store``.

    Returns
    -------
    xarray.Dataset
        Dimensions ``solution``, the swept parameters (``sweep`` for swept-sine tests) and ``frequency``; benchmark
        scenes: ``case``, ``engine``, ``rtol``. Every solution is on every frequency: a simulated one is NaN (flags
        ``not_applicable``) where it was not simulated, so plot it from :func:`split_groups`'s ``"/simulated"``
        (its own frequencies), as the file written by :func:`write_dataset` holds it.

    Raises
    ------
    KeyboardInterrupt
        On Ctrl-C, after the work in progress is cancelled (finished work stays in ``store``).
    vibroimpact.runs.cluster.ClusterLost
        When the dask scheduler goes away.
    RuntimeError
        When called by a worker process running the caller's script again (an unguarded call: it says what to write).

    Notes
    -----
    A script may call it at its top level with ``jobs > 1``: the workers do not run the script again as they start
    (:mod:`vibroimpact.runs.spawn_main`). A worker dask restarts later does; guard the call with
    ``if __name__ == "__main__":`` for that.
    """
    refuse_in_a_spawned_import("run_study")
    with quiet_calls(), Runner(jobs, scheduler, store, progress is not None) as runner:  # the study's bar, not each call's line
        if kind_named(scene.kind).shares_work:
            runner.start()  # a local cluster's workers start while this process imports the kind's code (~1 s sooner)
        kind = study_kind(scene)
        engines, batched = kind.engines(scene), batched_engines(kind, scene)
        prepare_engines(engines, progress, batched)
        runner.use_engines(engines, batched)
        dataset = kind.run(scene, progress, runner)
        reused = runner.reuse_line()
        if reused and progress is not None:
            progress(reused)  # the same line in every kind: what a resumed run took from its store
    dataset.attrs = dataset_header(scene, dataset.attrs) | {"study_kind": kind.name}
    if runner.worker_peak_memory:
        dataset.attrs["run_peak_memory_worker_bytes"] = runner.worker_peak_memory  # the largest dask worker
    return dataset.load() if load else dataset


# --------------------------------------------------------------------------------------------------------------------
# Writing datasets: atomic files (runs.output_files.atomic_path: a reader never sees half a file, a failed write leaves the
# previous one intact), netCDF with compression and CF-clean coordinates, and the provenance every dataset carries.
# --------------------------------------------------------------------------------------------------------------------

#: The attributes :func:`dataset_header` writes first in every dataset (and a kind's run never writes).
HEADER_ATTRIBUTES = ("title", "scene_name", "scene", "vibroimpact_version", "vibroimpact_source_sha256", "Conventions")


def dataset_header(scene: Scene, attrs: Mapping[str, Any]) -> dict[str, Any]:
    """``attrs`` (what a kind's run says of its dataset) after the header every dataset carries, in this order: the
    ``title`` its kind's row gives (:meth:`vibroimpact.scene.kinds.Kind.title_of`), ``scene_name``, the scene's text
    (``scene``) and :func:`provenance`. :func:`run_study` adds ``study_kind`` last.

    Raises
    ------
    ValueError
        Where ``attrs`` holds a header attribute (:data:`HEADER_ATTRIBUTES`: only this function writes them).
    """
    written = sorted(set(attrs) & {*HEADER_ATTRIBUTES, "study_kind"})
    if written:
        raise ValueError(f"the {scene.kind} kind's run wrote {', '.join(written)}: run_study writes the header of every dataset")
    header: dict[str, Any] = {"title": kind_named(scene.kind).title_of(scene), "scene_name": scene.name, "scene": scene.text, **provenance()}
    return header | dict(attrs)


def provenance() -> dict[str, str]:
    """What every dataset says about how it was made: the package version, its source and the conventions followed."""
    return {"vibroimpact_version": __version__, "vibroimpact_source_sha256": source_hash(), "Conventions": "CF-1.8"}


def netcdf_attribute(value: object, where: str) -> object:
    """``value`` as a netCDF attribute keeps it: numbers stay numbers, never the text of their repr.

    Sequences become one numpy array (the netCDF4 library would turn a list mixing numbers and text into the text of
    each entry, and a nested one into the repr of an array), booleans become int8 (netCDF has no boolean).

    Raises
    ------
    ValueError
        For a sequence mixing numbers and text, or nested (a writer's bug: netCDF would keep it as text).
    """
    if isinstance(value, (bool, np.bool_)):
        return np.int8(value)
    if isinstance(value, (list, tuple)):
        kinds = {"text" if isinstance(item, (str, bytes)) else "number" if isinstance(item, (int, float, np.number, np.bool_)) else type(item).__name__ for item in value}
        if len(kinds) > 1 or kinds - {"text", "number"}:
            raise ValueError(f"attribute of {where}: {value!r} mixes {sorted(kinds)}; netCDF keeps one flat array of numbers or of text")
        value = np.asarray(value)
    if isinstance(value, np.ndarray):
        if value.ndim > 1 or value.dtype == object:
            raise ValueError(f"attribute of {where}: a {value.ndim}-d {value.dtype} array; netCDF keeps one flat array of numbers or of text")
        return value.astype(np.int8) if value.dtype == np.bool_ else value
    return value


def netcdf_attributes(attrs: dict[Any, Any], where: str) -> dict[Any, Any]:
    """Every attribute of ``attrs`` through :func:`netcdf_attribute` (``where`` names their owner in errors)."""
    return {key: netcdf_attribute(value, f"{where}, {key}") for key, value in attrs.items()}


#: The netCDF group of a dataset's simulated solutions (:func:`split_groups`).
SIMULATED_GROUP = "simulated"
#: What the root group of a file with simulated solutions says of them (its ``comment``, and the attribute
#: ``simulated_solutions_group``).
SIMULATED_COMMENT = (
    f"The simulated solutions (time-domain engines) are in the netCDF group '{SIMULATED_GROUP}', on their own frequency "
    "axis (the frequencies they were simulated at), with the same variable names; this group holds the solutions "
    "computed on every frequency."
)
#: Flag meanings that say a variable does not apply at a point (the value a solution that does not compute it holds).
ABSENT_FLAGS = ("not_applicable", "not_computed")


def absent_value(variable: xr.DataArray | xr.Variable) -> object:
    """The value ``variable`` holds where it does not apply: NaN for a float variable, the flag meaning
    ``not_applicable`` or ``not_computed`` (:data:`ABSENT_FLAGS`) for a CF flag variable.

    Raises
    ------
    ValueError
        For any other variable (no value says "nothing here").
    """
    if variable.dtype.kind in "fc":
        return np.nan
    meanings = str(variable.attrs.get("flag_meanings", "")).split()
    values = np.atleast_1d(variable.attrs.get("flag_values", []))
    for meaning, value in zip(meanings, values):
        if meaning in ABSENT_FLAGS:
            return value
    raise ValueError(f"no value of {variable.dtype} variable {getattr(variable, 'name', '')!r} says that it does not apply (a float, or CF flags meaning one of {ABSENT_FLAGS})")


def _present(variable: xr.DataArray) -> xr.DataArray:
    """Where ``variable`` holds a value (not :func:`absent_value`)."""
    absent = absent_value(variable)
    return variable.notnull() if isinstance(absent, float) and np.isnan(absent) else variable != absent


def _simulated(dataset: xr.Dataset) -> tuple[list[str], np.ndarray]:
    """The dataset's simulated solutions (the time-domain engines among its ``solution``) and the mask of the
    frequencies they were simulated at (the attribute ``simulation_frequency_Hz``; without it, wherever one holds a
    value)."""
    if "solution" not in dataset.dims or "frequency" not in dataset.dims:
        return [], np.zeros(0, dtype=bool)
    simulated = [str(name) for name in dataset["solution"].values if name in ENGINE_SOLUTIONS]
    if not simulated:
        return [], np.zeros(0, dtype=bool)
    if "simulation_frequency_Hz" in dataset.attrs:
        return simulated, np.isin(dataset["frequency"].values, np.atleast_1d(dataset.attrs["simulation_frequency_Hz"]))
    mask = np.zeros(dataset.sizes["frequency"], dtype=bool)
    for variable in dataset.sel(solution=simulated).data_vars.values():
        if {"solution", "frequency"} <= set(variable.dims):
            mask |= np.asarray(_present(variable).any([d for d in variable.dims if d != "frequency"]).values)
    return simulated, mask


@suggest_keywords
def split_groups(dataset: xr.Dataset) -> dict[str, xr.Dataset]:
    """``dataset`` as :func:`write_dataset` stores it: netCDF group path -> dataset (what ``xarray.open_groups`` reads).

    A dataset without a simulated solution is one group, ``"/"``, as it is. Otherwise the solutions computed on every
    frequency (the closed forms) stay in ``"/"``, and the simulated ones (the time-domain engines) go to
    ``"/simulated"`` (:data:`SIMULATED_GROUP`) on their own ``frequency`` coordinate, the frequencies they were
    simulated at, with the same variable names, dimension names, other coordinates and attributes: there
    ``x1_amplitude.sel(solution="exact").plot()`` draws a curve, not isolated points between NaNs. A variable that
    holds no value over one group's solutions (all NaN, or all ``not_applicable``: ``converged`` or ``lyapunov_*`` for
    the closed forms, ``stable`` or ``phase`` for the engines) is left out of that group; one with no value in either
    goes with the simulations. The root's attributes say where the simulations are (``simulated_solutions_group`` and
    a sentence in ``comment``). In each group the labelled dimensions (strings, or numbers out of order) are index
    dimensions, their labels in ``<dimension>_label`` (:func:`vibroimpact.runs.labels.encode_labels`).
    :func:`join_groups` gives ``dataset`` back.
    """
    simulated, on_axis = _simulated(dataset)
    if not simulated:
        return {"/": encode_labels(dataset)}
    closed = [str(name) for name in dataset["solution"].values if name not in simulated]
    per_solution = [name for name, variable in dataset.data_vars.items() if "solution" in variable.dims]
    root = dataset.sel(solution=closed)
    group = dataset.sel(solution=simulated).isel(frequency=np.flatnonzero(on_axis))
    # whether each variable holds a value in each group: one computation over a lazy dataset (which reads the store
    # once), not one per variable
    holds = xr.Dataset({(part, name): _present(source[name]).any() for part, source in (("root", root), ("group", group)) for name in per_solution}).compute()
    in_root = [name for name in per_solution if closed and bool(holds[("root", name)])]
    in_group = [name for name in per_solution if name not in in_root or bool(holds[("group", name)])]
    root = root.drop_vars([name for name in per_solution if name not in in_root])
    if not closed:
        root = root.drop_dims("solution")
    comment = str(dataset.attrs.get("comment", ""))
    root.attrs = {**dataset.attrs, "simulated_solutions_group": SIMULATED_GROUP, "comment": f"{comment} {SIMULATED_COMMENT}".strip()}
    group = group[in_group]
    group.attrs = {"comment": "The simulated solutions of the root group's study, at the frequencies they were simulated at (the root's simulation_frequency_Hz)."}
    return {"/": encode_labels(root), f"/{SIMULATED_GROUP}": encode_labels(group)}


@suggest_keywords
def join_groups(groups: Mapping[str, xr.Dataset]) -> xr.Dataset:
    """The one dataset of :func:`split_groups`'s groups (or of ``xarray.open_groups`` on a file :func:`write_dataset`
    wrote): every solution on the root's frequency axis, the simulated ones ``not_applicable`` or NaN at the
    frequencies they were not simulated at, a variable left out of a group ``not_applicable`` or NaN for its
    solutions. The root's solutions come first; the labels of the groups' dimensions are their coordinates again
    (:func:`vibroimpact.runs.labels.decode_labels`), and a flag variable a file masked (xarray reads an integer
    variable with a ``_FillValue`` as floats, NaN at the fill value) is integers again."""
    root = _unmasked(decode_labels(groups["/"]))
    group = groups.get(f"/{SIMULATED_GROUP}")
    if group is None:
        return root
    group = _unmasked(decode_labels(group))
    parts = [part for part in (root, group) if "solution" in part.dims]
    solutions = np.concatenate([part["solution"].values for part in parts])
    order, frequency = pd.Index(solutions), root.indexes["frequency"]
    names = list(dict.fromkeys(name for part in parts for name, variable in part.data_vars.items() if "solution" in variable.dims))
    joined = root.drop_dims("solution") if "solution" in root.dims else root.copy()
    for name in names:
        template = next(part[name] for part in parts if name in part)
        shape = tuple(solutions.size if dim == "solution" else frequency.size if dim == "frequency" else template.sizes[dim] for dim in template.dims)
        values = np.full(shape, absent_value(template), dtype=template.dtype)
        for part in parts:
            if name in part:
                where = [order.get_indexer(part.indexes["solution"]) if dim == "solution" else frequency.get_indexer(part.indexes["frequency"]) if dim == "frequency" else np.arange(template.sizes[dim]) for dim in template.dims]
                values[np.ix_(*where)] = part[name].transpose(*template.dims).values
        joined[name] = xr.Variable(template.dims, values, template.attrs)
    joined = joined.assign_coords(solution=("solution", solutions, (root if "solution" in root.dims else group)["solution"].attrs))
    attrs = dict(root.attrs)
    attrs.pop("simulated_solutions_group", None)
    comment = str(attrs.pop("comment", "")).removesuffix(SIMULATED_COMMENT).strip()
    joined.attrs = {**attrs, **({"comment": comment} if comment else {})}
    return joined


def _unmasked(dataset: xr.Dataset) -> xr.Dataset:
    """``dataset`` with every integer variable that xarray read as floats (masked at its ``_FillValue``) back to its
    stored integers, the fill value where it read NaN and ``_FillValue`` among its attributes, as it was written."""
    masked = {}
    for name, variable in dataset.data_vars.items():
        stored, fill = variable.encoding.get("dtype"), variable.encoding.get("_FillValue")
        if stored is not None and np.dtype(stored).kind in "iu" and variable.dtype.kind == "f" and fill is not None:
            values = np.where(np.isnan(variable.values), fill, variable.values).astype(stored)
            masked[name] = xr.Variable(variable.dims, values, {**variable.attrs, "_FillValue": np.asarray(fill, dtype=stored)[()]})
    return dataset.assign(masked) if masked else dataset


@suggest_keywords
def read_dataset(path: str | Path) -> xr.Dataset:
    """The dataset :func:`write_dataset` wrote at ``path``, loaded, its groups joined (:func:`join_groups`): the one
    dataset :func:`run_study` returned, which the report pages draw from."""
    groups = xr.open_groups(path)
    try:
        return join_groups({key: part.load() for key, part in groups.items()})
    finally:
        for part in groups.values():
            part.close()


def _netcdf_encoding(dataset: xr.Dataset) -> tuple[xr.Dataset, dict[str, dict[str, object]]]:
    """``dataset`` with netCDF attributes (:func:`netcdf_attributes`) and its encoding: compressed variables, and CF
    2.5.1: coordinate variables carry no _FillValue (xarray adds one to every float variable unless told not to)."""
    dataset = dataset.copy()  # shallow: the attributes are replaced, the data shared
    dataset.attrs = netcdf_attributes(dataset.attrs, "the dataset")
    for name, variable in dataset.variables.items():
        variable.attrs = netcdf_attributes(variable.attrs, f"variable {name}")
    encoding: dict[str, dict[str, object]] = {str(name): {"zlib": True, "complevel": 4} for name in dataset.data_vars}
    encoding |= {str(name): {"_FillValue": None} for name in dataset.coords if dataset[name].dtype.kind == "f"}
    return dataset, encoding


@suggest_keywords
def write_dataset(dataset: xr.Dataset, path: str | Path) -> Path:
    """Write ``dataset`` to netCDF atomically: a temporary file in the same folder, then a rename.

    The simulated solutions go to the group ``simulated``, on the frequencies they were simulated at
    (:func:`split_groups`); :func:`read_dataset` reads the file back as ``dataset``. A reader never sees a
    half-written file, and an interrupted run leaves the previous file intact.
    """
    path = Path(path)
    groups = split_groups(dataset)
    try:
        with atomic_path(path) as temporary:
            for key, part in groups.items():
                part, encoding = _netcdf_encoding(part)
                if key == "/" and not part.attrs.get("history"):
                    stamp = datetime.now(timezone.utc).strftime("%Y-%m-%dT%H:%M:%SZ")
                    part = part.assign_attrs(history=f"{stamp} vibroimpact {__version__}: {part.attrs.get('title', 'dataset')} written")
                part.to_netcdf(temporary, mode="w" if key == "/" else "a", group=None if key == "/" else key, engine="netcdf4", format="NETCDF4", encoding=encoding)
    except (OSError, RuntimeError) as error:  # the netCDF library says "NetCDF: HDF error" for a full disk
        raise OSError(f"writing {path} failed ({error}); {_free_space(path.parent)}: free space there or choose another --out (finished work is kept in the store)") from None
    return path


def _free_space(folder: Path) -> str:
    """'N MB free on its disk', or why that is not known."""
    import shutil

    try:
        return f"{shutil.disk_usage(folder).free / 1e6:.0f} MB free on its disk"
    except OSError as error:
        return f"its free space is unknown ({error.strerror})"
