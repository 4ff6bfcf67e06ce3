"""Every engine by name: the one vocabulary of scenes, studies, benchmarks, the cost estimate and the tests.

An entry names the class that implements the engine (imported on first use, so that a scene can check engine names
without loading a solver library), what it can do (:class:`Capabilities`: the contact law it solves, exact
Jacobians, an exact flow, tolerances), and the options it is built with. Code asks an engine's capabilities, never
its name. Adding an engine is one module plus one line here::

    "my_engine": EngineSpec("vibroimpact.engines.my_engine:MyEngine", Capabilities(RIGID), "what it is"),
"""

from __future__ import annotations

import importlib
import sys
from dataclasses import dataclass, field, fields
from types import MappingProxyType
from typing import Any, Mapping

from vibroimpact.engines.settings import EngineSettings
from vibroimpact.model.contact import BUMPER, RIGID
from vibroimpact.model.keywords import suggest_keywords

__all__ = ["RIGID", "BUMPER", "Capabilities", "CAPABILITIES", "EngineSpec", "ENGINES", "engine_names", "stepped_solutions", "engine_spec", "make_engine", "engine_for", "FIRST_COMPILE_TIME", "compile_notice"]

# RIGID and BUMPER, the contact laws an engine can solve (the momentary-impact stop and the Kelvin-Voigt bumper), are
# the model's names (vibroimpact.model.contact), re-exported here beside the capabilities that use them.


@suggest_keywords
@dataclass(frozen=True)
class Capabilities:
    """What an engine can do, as the code that runs it asks.

    Attributes
    ----------
    contact : str
        :data:`RIGID` or :data:`BUMPER`: the contact law of the problems it integrates.
    exact_jacobians : bool
        ``integrate(..., jacobians=True)`` also returns the exact Jacobian of each period's stroboscopic map.
    exact_flow : bool
        Its trajectories are the exact piecewise-linear flow (no tolerance): an orbit shot on the exact stroboscopic
        map is its own steady state, measured without confirming it by marching.
    tolerance_free : bool
        Its tolerances change nothing: one run stands for every tolerance of a benchmark.
    stepped_solution : bool
        Offered as a time-domain solution of stepped studies under its registry name.
    sweeps : bool
        Also a sweeping engine: ``sweep(problem, sample_rate, state, progress)`` runs a swept sine (a closed-form
        engine cannot: a chirp has no closed-form particular solution).
    compiled_period : bool
        ``compiled_period(problem)`` gives its stroboscopic map over one period from t = 0 as its compiled loop alone
        computes it, without the general map's Python around each evaluation (a
        :class:`~vibroimpact.engines.compliant.exact.CompiledPeriod`, shot as
        :class:`~vibroimpact.orbits.bumper_map.CompiledPeriodMap`).
    batched : bool
        ``run_many(problems, case_of, starts, transient, strobes, scales, max_period)`` runs many starts of problems of
        one layout in one compiled call, bit for bit its single runs (:mod:`~vibroimpact.engines.batch`).
    compiled : bool
        Its kernels are compiled by numba on first use (tens of seconds) and kept in numba's on-disk cache: its module's
        ``kernels_cached(batched)`` says whether the cache holds them and ``prepare_kernels(batched)`` compiles them in the calling
        process (or loads them from the cache), returning the seconds spent compiling (:meth:`EngineSpec.prepare_kernels`).
    """

    contact: str
    exact_jacobians: bool = False
    exact_flow: bool = False
    tolerance_free: bool = False
    stepped_solution: bool = False
    sweeps: bool = False
    compiled_period: bool = False
    batched: bool = False
    compiled: bool = False

    def __post_init__(self) -> None:
        if self.contact not in (RIGID, BUMPER):
            raise ValueError(f"contact = {self.contact!r} is not allowed: use {RIGID!r} or {BUMPER!r}")
        if self.exact_flow and not self.tolerance_free:
            raise ValueError("an engine with an exact flow has no tolerance: tolerance_free must be True")


#: The names of what an engine can do beyond its contact law: the boolean fields of :class:`Capabilities`.
CAPABILITIES = tuple(item.name for item in fields(Capabilities) if item.name != "contact")


@dataclass(frozen=True)
class EngineSpec:
    """One registered engine.

    Attributes
    ----------
    target : str
        ``module:class`` of the engine; the class is called as ``cls(settings, **options)``.
    capabilities : Capabilities
        What it can do; the built engine carries them (``engine.capabilities``).
    description : str
        One line for listings.
    options : mapping
        Fixed keyword arguments of the class (a solver family, a method).
    settings_method : str or None
        When set, the CVODE method (``adams`` or ``bdf``) the engine always uses, whatever the settings say.
    """

    target: str
    capabilities: Capabilities
    description: str
    options: Mapping[str, Any] = field(default_factory=lambda: MappingProxyType({}))
    settings_method: str | None = None

    def build(self, settings: EngineSettings) -> Any:
        """The engine with ``settings`` (its method replaced by :attr:`settings_method` when that is set)."""
        module_name, _, class_name = self.target.partition(":")
        engine_class = getattr(importlib.import_module(module_name), class_name)
        if self.settings_method is not None and settings.method != self.settings_method:
            settings = EngineSettings(**{**settings.__dict__, "method": self.settings_method})
        engine = engine_class(settings, **self.options)
        engine.capabilities = self.capabilities
        return engine

    @property
    def contact(self) -> str:
        """:data:`RIGID` or :data:`BUMPER`: the contact law of the problems it integrates."""
        return self.capabilities.contact

    def kernels_cached(self, batched: bool = False) -> bool:
        """Whether numba's on-disk cache holds the engine's compiled kernels, with ``batched`` its batch entry's too
        (True for an engine with none to compile)."""
        if not self.capabilities.compiled:
            return True
        cached: bool = self._module().kernels_cached(batched and self.capabilities.batched)
        return cached

    def prepare_kernels(self, batched: bool = False) -> float:
        """Compile the engine's kernels in this process, or load them from numba's on-disk cache, with ``batched`` its
        batch entry too (where it has one; a study that runs many starts at once asks for it); return the seconds
        spent compiling [s] (0 where they were cached, or the engine has none)."""
        if not self.capabilities.compiled:
            return 0.0
        seconds: float = self._module().prepare_kernels(batched and self.capabilities.batched)
        return seconds

    def _module(self) -> Any:
        return importlib.import_module(self.target.partition(":")[0])


#: A rigid-stop engine that integrates to a tolerance; the bumper's.
INTEGRATOR, BUMPER_INTEGRATOR = Capabilities(RIGID), Capabilities(BUMPER, sweeps=True)
#: The exact engine's algorithm: the closed-form flow.
EXACT_FLOW = Capabilities(RIGID, exact_flow=True, tolerance_free=True)


def _solve_ivp(method: str) -> EngineSpec:
    return EngineSpec("vibroimpact.engines.momentary:SolveIvpEngine", INTEGRATOR, f"scipy solve_ivp ({method}) with terminal events and restarts: a comparison baseline", MappingProxyType({"method": method}))


#: name -> engine. ``momentary`` uses the method of its settings; the suffixed names fix it.
ENGINES: Mapping[str, EngineSpec] = MappingProxyType(
    {
        "exact": EngineSpec("vibroimpact.engines.exact:ExactEngine", Capabilities(RIGID, exact_jacobians=True, exact_flow=True, tolerance_free=True, stepped_solution=True, batched=True, compiled=True), "piecewise-exact closed-form flow with guaranteed contact search, compiled: the reference"),
        "exact_python": EngineSpec("vibroimpact.engines.exact_python:PythonExactEngine", EXACT_FLOW, "the exact engine's algorithm in pure Python: its cross-check and speed baseline"),
        "momentary": EngineSpec("vibroimpact.engines.momentary:MomentaryEngine", Capabilities(RIGID, stepped_solution=True), "SUNDIALS CVODE with contact events and a grazing guard (method from the settings)"),
        "momentary_adams": EngineSpec("vibroimpact.engines.momentary:MomentaryEngine", INTEGRATOR, "SUNDIALS CVODE, Adams, with contact events and a grazing guard", settings_method="adams"),
        "momentary_bdf": EngineSpec("vibroimpact.engines.momentary:MomentaryEngine", INTEGRATOR, "SUNDIALS CVODE, BDF, with contact events and a grazing guard", settings_method="bdf"),
        "solve_ivp_RK45": _solve_ivp("RK45"),
        "solve_ivp_DOP853": _solve_ivp("DOP853"),
        "solve_ivp_LSODA": _solve_ivp("LSODA"),
        "solve_ivp_Radau": _solve_ivp("Radau"),
        "solve_ivp_BDF": _solve_ivp("BDF"),
        "compliant": EngineSpec("vibroimpact.engines.compliant.ida:CompliantEngine", Capabilities(BUMPER, stepped_solution=True, sweeps=True), "Kelvin-Voigt bumper through SUNDIALS IDA, one solver per contact mode"),
        "compliant_ida": EngineSpec("vibroimpact.engines.compliant.ida:CompliantEngine", BUMPER_INTEGRATOR, "the engine compliant, under the name benchmark scenes use"),
        "compliant_cvode_adams": EngineSpec("vibroimpact.engines.compliant.ida:CompliantCvodeEngine", BUMPER_INTEGRATOR, "Kelvin-Voigt bumper through SUNDIALS CVODE (Adams)", settings_method="adams"),
        "compliant_cvode_bdf": EngineSpec("vibroimpact.engines.compliant.ida:CompliantCvodeEngine", BUMPER_INTEGRATOR, "Kelvin-Voigt bumper through SUNDIALS CVODE (BDF)", settings_method="bdf"),
        "compliant_exact": EngineSpec("vibroimpact.engines.compliant.exact:CompliantExactEngine", Capabilities(BUMPER, exact_jacobians=True, exact_flow=True, tolerance_free=True, stepped_solution=True, compiled_period=True, batched=True, compiled=True), "Kelvin-Voigt bumper in closed form per contact mode with guaranteed switch search, compiled: the bumper's reference"),
    }
)


def engine_names(contact: str | None = None) -> tuple[str, ...]:
    """Registered names, in registry order; only those solving ``contact`` (:data:`RIGID`, :data:`BUMPER`) if given."""
    return tuple(name for name, spec in ENGINES.items() if contact is None or spec.contact == contact)


def stepped_solutions() -> tuple[str, ...]:
    """Engines offered as time-domain solutions of stepped studies, in registry order."""
    return tuple(name for name, spec in ENGINES.items() if spec.capabilities.stepped_solution)


def engine_spec(name: str) -> EngineSpec:
    """The entry of ``name``; ``ValueError`` naming the registered engines if there is none."""
    try:
        return ENGINES[name]
    except KeyError:
        raise ValueError(f"engine {name!r} is unknown: use one of {', '.join(ENGINES)}") from None


#: What the first use of a compiled engine costs on a machine, numba compiling its kernels into its on-disk cache
#: (measured: ``exact`` 25-46 s on a quiet 2-core machine, 57 s and its batch entry 15 s more at load 3); later runs
#: load them in ~0.1 s. The one figure the package states (the README, the run's line, this notice).
FIRST_COMPILE_TIME = "~30-60 s"
_ANNOUNCED: set[str] = set()


def compile_notice(name: str) -> str:
    """The line said before an engine's kernels are compiled (the first use on a machine)."""
    return f"compiling the {name} engine's kernels (first use on this machine only, {FIRST_COMPILE_TIME}; later runs load them from numba's cache)"


@suggest_keywords
def make_engine(name: str, settings: EngineSettings = EngineSettings()) -> Any:
    """The engine registered under ``name``, built with ``settings``. The first one built of an engine whose kernels
    are not compiled yet says so on a terminal (:func:`compile_notice`): its first use waits for numba."""
    spec = engine_spec(name)
    if spec.capabilities.compiled and name not in _ANNOUNCED and sys.stderr is not None and sys.stderr.isatty() and not spec.kernels_cached():
        _ANNOUNCED.add(name)
        print(compile_notice(name), file=sys.stderr, flush=True)
    return spec.build(settings)


def engine_for(contact: str, capability: str) -> str:
    """The name of the first registered engine that solves ``contact`` (:data:`RIGID`, :data:`BUMPER`) and has
    ``capability`` (one of :data:`CAPABILITIES`): e.g. ``exact_jacobians`` for shooting and continuation,
    ``exact_flow`` for a contact law's reference.

    Raises
    ------
    ValueError
        ``capability`` is not one of :data:`CAPABILITIES`, or no registered engine solves ``contact`` with it.
    """
    if capability not in CAPABILITIES:
        raise ValueError(f"contact = {contact!r}, capability = {capability!r}: the capability is unknown: use one of {', '.join(CAPABILITIES)}")
    for name, spec in ENGINES.items():
        if spec.contact == contact and getattr(spec.capabilities, capability):
            return name
    raise ValueError(f"contact = {contact!r}, capability = {capability!r}: no registered engine solves the contact law with the capability (contact laws {RIGID!r}, {BUMPER!r}; capabilities {', '.join(CAPABILITIES)})")
