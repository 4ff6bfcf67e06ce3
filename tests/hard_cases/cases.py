"""The hard cases, and the engines every case runs on.

Each :class:`HardCase` names a problem, a start and a length, and for EVERY engine of :data:`ENGINE_NAMES` either
an :class:`Expect` (what must hold for that engine; anything relaxed says why in ``note``) or a :class:`NotRun`
(why the engine does not apply). ``test_hard_cases.test_every_case_names_every_engine`` enforces it: no engine is
left out silently.

What is always checked, whatever the case (``checks.py``): the run ends within the case's timeout; every impact
has a positive pre-impact speed; rigid engines obey the contact law at every impact (X2 = Delta, X2'+ = -R X2'-,
impulse M2 (1 + R) X2'-, or X2'+ = 0 and impulse M2 X2'- when the impact ends a chatter in sticking); the compliant
engine's contacts all release and its penetration stays within what the bumper's stiffness allows.

Engines and their settings (the same in every case):

=====================================  ==========================================================  ========================
name (:mod:`vibroimpact.engines.registry`)  engine                                              tolerances
=====================================  ==========================================================  ========================
exact                                  ``ExactEngine`` (closed form, the reference)                round-off
momentary_adams, momentary_bdf         ``MomentaryEngine`` (CVODE with grazing guard)              rtol 1e-10, atol 1e-14 m
solve_ivp_DOP853, solve_ivp_LSODA      ``SolveIvpEngine`` (no grazing guard, on purpose)           rtol 1e-10, atol 1e-14 m
solve_ivp_Radau                        ``SolveIvpEngine`` (~1 s per simulated s at 1e-10)          rtol 1e-8, atol 1e-12 m
compliant                              ``CompliantEngine`` (IDA, Kelvin-Voigt bumper, 5 kHz)       rtol 1e-9, atol 1e-13 m
compliant_exact                        ``CompliantExactEngine`` (the same bumper in closed form)   round-off
=====================================  ==========================================================  ========================

The compliant engines run each case's problem with the case's bumper in place of the rigid stop; both are held to
the same expectations (those of the bumper model against the rigid stop).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace
from typing import Mapping

import numpy as np

from vibroimpact.model.contact import KelvinVoigtBumper, RigidStop, loss_factor_from_restitution, restitution_from_loss_factor
from vibroimpact.model.excitation import HarmonicForce
from vibroimpact.model.problem import ImpactProblem
from vibroimpact.engines.base import Engine
from vibroimpact.engines.registry import RIGID as RIGID_LAW
from vibroimpact.engines.registry import engine_spec, make_engine
from vibroimpact.engines.settings import EngineSettings
from vibroimpact.analysis.linear import paper_linear_response
from vibroimpact.model.system import PAPER_SYSTEM, TwoDofSystem

from tests.conftest import PAPER_AMPLITUDE, PAPER_CLEARANCE
from tests.engine_cases import linear_state, pgf_start

__all__ = ["ENGINE_NAMES", "RIGID", "SOLVE_IVP", "Expect", "NotRun", "HardCase", "CASES", "build_engine", "matching_bumper"]

#: Registered engines of the table, and each one's settings.
ENGINE_NAMES = ("exact", "momentary_adams", "momentary_bdf", "solve_ivp_DOP853", "solve_ivp_LSODA", "solve_ivp_Radau", "compliant", "compliant_exact")
RIGID = tuple(name for name in ENGINE_NAMES if engine_spec(name).contact == RIGID_LAW)
SOLVE_IVP = ("solve_ivp_DOP853", "solve_ivp_LSODA", "solve_ivp_Radau")

TIGHT = EngineSettings(rtol=1e-10, atol=1e-14)
RADAU = EngineSettings(rtol=1e-8, atol=1e-12)
COMPLIANT = EngineSettings(rtol=1e-9, atol=1e-13)
SETTINGS = {
    "exact": EngineSettings(),
    "momentary_adams": TIGHT,
    "momentary_bdf": TIGHT,
    "solve_ivp_DOP853": TIGHT,
    "solve_ivp_LSODA": TIGHT,
    "solve_ivp_Radau": RADAU,
    "compliant": COMPLIANT,
    "compliant_exact": EngineSettings(),
}
#: Bumper of the compliant engine unless a case sets its own: stiff enough to be compared with the rigid stop.
BUMPER_FREQUENCY = 5000.0


def matching_bumper(problem: ImpactProblem, frequency: float = BUMPER_FREQUENCY) -> KelvinVoigtBumper:
    """The bumper at the problem's clearance whose one-collision restitution is the problem's R."""
    return KelvinVoigtBumper(problem.clearance, frequency, loss_factor_from_restitution(problem.restitution))


@dataclass(frozen=True)
class Expect:
    """What must hold for one engine in one case (``None``: not required).

    Attributes
    ----------
    impacts : {'same', 'at_least', 'none', 'free'}
        Impact (contact) count: equal to exact's; at least exact's; zero; or not required (``note`` says why).
    times : float or None
        Largest |t - t_exact| over the impacts [s] (needs the same count).
    states : float or None
        Largest |y - y_exact| over the strobes, as a fraction of each component's largest |y_exact| [-].
    x1 : float or None
        Relative error of |X1| (fundamental harmonic over the case's last ``measure_periods``) against exact's [-].
    energy : float or None
        Rigid engines: energy change = input work - viscous dissipation - impact loss, to this fraction of the
        work [-] (the flow between events is exact, so this checks event states and the contact map).
    penetration : float or None
        Rigid engines: X2 - Delta at every strobe and segment start, and along the exact flow of every free segment
        (a missed contact shows there), at most this fraction of the length scale Delta + w^-1 velocity_scale [-].
    sticking : bool
        As many sticks and releases as exact, and the same stuck time to 1e-6.
    reference : float or None
        Agreement with the case's analytic reference (``HardCase.reference``) to this tolerance.
    restitution : float or None
        Compliant engine: |-X2'+ / X2'- - R(xi_b)| at every contact entered faster than 0.1 of the velocity scale
        (slower ones are shaped by the absorber's spring, not by the bumper alone) [-].
    impulse : float or None
        Compliant engine: |J - M2 (X2'- - X2'+)| / (M2 (X2'- - X2'+)) at those contacts (the absorber spring's
        impulse over the contact is the difference) [-].
    note : str
        Why a requirement is relaxed for this engine.
    """

    impacts: str = "same"
    times: float | None = None
    states: float | None = None
    x1: float | None = None
    energy: float | None = None
    penetration: float | None = 1e-12
    sticking: bool = False
    reference: float | None = None
    restitution: float | None = None
    impulse: float | None = None
    note: str = ""

    def __post_init__(self) -> None:
        if self.impacts not in ("same", "at_least", "none", "free"):
            raise ValueError(f"impacts = {self.impacts!r} is not allowed: use 'same', 'at_least', 'none' or 'free'")
        if self.impacts == "free" and not self.note:
            raise ValueError("impacts = 'free' must say why in note")


@dataclass(frozen=True)
class NotRun:
    """The engine does not apply to the case, and why."""

    reason: str


@dataclass(frozen=True)
class HardCase:
    """One hard case: a problem, a start, a length, and per engine what must hold.

    Attributes
    ----------
    id : str
        Readable test id.
    hard : str
        What makes it hard.
    problem : ImpactProblem
        System, rigid stop and excitation (the compliant engine runs it with ``bumper`` as the contact).
    start : (float, ndarray)
        Start time [s] and state (X1, X2, X1', X2').
    periods : int
        Periods integrated.
    expect : mapping
        Engine name -> :class:`Expect` or :class:`NotRun`, for every name of :data:`ENGINE_NAMES`.
    reference : {'linear', 'pgf', 'scaled', 'touch'} or None
        Analytic reference, independent of the exact engine: the linear steady state (no contact: strobe states
        equal it, tolerance relative to each component's amplitude); the PGF one-impact orbit (one impact per period
        with its impulse, relative tolerance); the same case at the paper's scale (``scaled_from``), whose exact
        impact times and scaled strobe states must be reproduced (tolerance relative to a period and to the scale);
        a grazing touch (at least one contact, the first slower than the tolerance times the velocity scale).
    bumper : KelvinVoigtBumper or None
        Bumper of the compliant engine (default: :func:`matching_bumper` at :data:`BUMPER_FREQUENCY`).
    timeout : float
        Per-engine test timeout [s] (a hang fails the test).
    slow : bool
        Excluded from the default run.
    long : bool
        Every engine's row in the ``hard`` tier, none in the default one (a long run whose ground the default tier
        covers with shorter cases; the ``slow`` tier runs it 20 times longer).
    measure_periods : int
        Last periods over which the X1 fundamental is compared.
    scaled_from : (ImpactProblem, float) or None
        For ``reference='scaled'``: the problem at the paper's scale and the factor from it to this one.
    """

    id: str
    hard: str
    problem: ImpactProblem
    start: tuple[float, np.ndarray]
    periods: int
    expect: Mapping[str, Expect | NotRun]
    reference: str | None = None
    bumper: KelvinVoigtBumper | None = None
    timeout: float = 60.0
    slow: bool = False
    long: bool = False
    measure_periods: int = 10
    scaled_from: tuple[ImpactProblem, float] | None = field(default=None, repr=False)

    def compliant_bumper(self) -> KelvinVoigtBumper:
        """The compliant engine's bumper."""
        return self.bumper if self.bumper is not None else matching_bumper(self.problem)

    def problem_for(self, engine: str) -> ImpactProblem:
        """The case's problem with the contact law ``engine`` solves."""
        return self.problem if engine_spec(engine).contact == RIGID_LAW else replace(self.problem, contact=self.compliant_bumper())


def build_engine(name: str) -> Engine:
    """The registered engine ``name`` with the table's settings."""
    if name not in SETTINGS:
        raise ValueError(f"engine {name!r} is not in the table: use one of {', '.join(ENGINE_NAMES)}")
    return make_engine(name, SETTINGS[name])


def per_engine(
    exact: Expect | NotRun,
    momentary: Expect | NotRun,
    solve_ivp: Expect | NotRun,
    compliant: Expect | NotRun,
    radau: Expect | NotRun | None = None,
) -> dict[str, Expect | NotRun]:
    """Expectations by family: ``momentary`` for momentary_adams and momentary_bdf, ``solve_ivp`` for
    solve_ivp_DOP853, solve_ivp_LSODA (and solve_ivp_Radau unless ``radau`` is given), ``compliant`` for both
    bumper engines."""
    return {
        "exact": exact,
        "momentary_adams": momentary,
        "momentary_bdf": momentary,
        "solve_ivp_DOP853": solve_ivp,
        "solve_ivp_LSODA": solve_ivp,
        "solve_ivp_Radau": solve_ivp if radau is None else radau,
        "compliant": compliant,
        "compliant_exact": compliant,
    }


def _rest() -> tuple[float, np.ndarray]:
    return 0.0, np.zeros(4)


def _linear(problem: ImpactProblem) -> tuple[float, np.ndarray]:
    return 0.0, linear_state(problem)


def _pgf(frequency: float, restitution: float, clearance: float = PAPER_CLEARANCE, system: TwoDofSystem = PAPER_SYSTEM) -> tuple[ImpactProblem, tuple[float, np.ndarray]]:
    problem, state, t0, _orbit = pgf_start(frequency, restitution, clearance, system)
    return problem, (t0, state)


def _grazing(margin: float, phase: float) -> ImpactProblem:
    """30 Hz, R = 0.9: the linear orbit's largest X2 is ``margin`` short of the stop (negative: beyond it)."""
    amplitude_x2 = PAPER_AMPLITUDE * abs(paper_linear_response(PAPER_SYSTEM, omega=2 * math.pi * 30.0, amplitude=1.0).x2)
    return ImpactProblem(PAPER_SYSTEM, RigidStop(amplitude_x2 + margin, 0.9), HarmonicForce(PAPER_AMPLITUDE, 30.0, phase=phase))


UNDAMPED = TwoDofSystem(m1=1.0, m2=0.1, k1=25_000.0, k2=4_300.0)
RESONANCES = tuple(w / (2 * math.pi) for w in PAPER_SYSTEM.natural_angular_frequencies())  # 23.02, 36.07 Hz
ANTIRESONANCE = PAPER_SYSTEM.antiresonance_angular_frequency() / (2 * math.pi)  # 33.00 Hz
OVERDAMPED = 2.0  # bumper loss factor xi_b
TINY = 1e-7  # scale of the near-zero amplitude case
HUGE = 1e3  # scale of the very large amplitude case



# --------------------------------------------------------------------------------------------------- what holds
#: Tolerances are ~10x (at least 3x) the values measured on this machine; the docstrings of the cases give them.


def exact(**changes: object) -> Expect:
    """The reference itself: its energy balance closes to round-off and it never passes the stop."""
    return replace(Expect(energy=1e-11, penetration=1e-12), **changes)  # type: ignore[arg-type]


def integrated(**changes: object) -> Expect:
    """An integrator at rtol 1e-10 (Radau 1e-8) on motion that is not sensitive: same impacts as exact, impact times
    to 1e-8 s, strobe states to 1e-6 of their scale, |X1| to 1e-6, energy balance to 1e-5 of the work, the exact flow
    from its event states never more than 1e-6 of the length scale beyond the stop (measured: <= 3e-10 s, 4e-7,
    4e-7, 6e-7 for BDF, the least accurate; the others are 10-100x closer)."""
    return replace(Expect(times=1e-8, states=1e-6, x1=1e-6, energy=1e-5, penetration=1e-6), **changes)  # type: ignore[arg-type]


NOT_FOUND_GRAZING = (
    "solve_ivp engines are not required to find grazing contacts: they have no grazing guard, on purpose (they are "
    "the baselines the momentary engine is measured against); DOP853, LSODA and Radau all miss this 0.5 nm touch. "
    "What holds: they end, the contact law at the impacts they find, the energy balance"
)
BUMPER_ONLY = "a bumper case: the rigid integrators run this stable 25 Hz orbit in long-500-periods"
RADAU_COST = "Radau costs ~1 s per simulated second even at rtol 1e-8 (~25 s here): its event loop is DOP853's and LSODA's"


def _cases() -> list[HardCase]:
    cases: list[HardCase] = []
    add = cases.append

    # grazing: the linear orbit's top just beyond (0.5 nm) or short of the stop; two phases of the step grid
    for phase in (0.0, 2.0):
        touch = _grazing(-5e-10, phase)
        add(HardCase(
            f"grazing-touch-phase{phase:g}", "the linear orbit passes 0.5 nm beyond the stop (a touch lasting ~5 us)", touch, _linear(touch), 3,
            per_engine(
                exact(reference=1e-3),
                # after a touch at ~0 speed the state's error is the square root of the position error: no strobe states
                integrated(times=2e-7, states=None, x1=1e-4, reference=1e-3, note="after the touch the motion's error is ~sqrt(position error): times to 2e-7 s (measured 3e-8), |X1| to 1e-4 (9e-6)"),
                integrated(impacts="free", times=None, states=None, x1=None, note=NOT_FOUND_GRAZING),
                Expect(times=1e-7, x1=1e-2, note="touch found at exact's time (measured 1.5e-9 s); |X1| to 1 % (1e-3): a 5 kHz bumper"),
            ),
            reference="touch",
        ))
    miss = _grazing(5e-10, 0.0)
    add(HardCase(
        "grazing-miss", "the linear orbit stays 0.5 nm short of the stop: no engine may report a contact", miss, _linear(miss), 3,
        per_engine(exact(impacts="none", reference=1e-11), integrated(impacts="none", states=1e-5, reference=1e-5), integrated(impacts="none", states=1e-5, reference=1e-5), Expect(impacts="none", reference=1e-4)),
        reference="linear",
    ))

    # chattering towards sticking: 10 Hz, Delta = 0.1 mm below the primary mass's 0.47 mm motion
    chatter_note = (
        "how many impacts of a chatter are resolved before sticking depends on the sticking threshold and on each "
        "engine's impact-time error (186-196 against exact's 194): sticks, releases and stuck time are compared"
    )
    for restitution in (0.0, 0.05):
        problem = ImpactProblem(PAPER_SYSTEM, RigidStop(1e-4, restitution), HarmonicForce(PAPER_AMPLITUDE, 10.0))
        rigid_impacts = "same" if restitution == 0.0 else "free"  # exact: the table's input R
        note = "" if restitution == 0.0 else chatter_note  # exact: the table's input R
        times = 1e-7 if restitution == 0.0 else None  # exact: the table's input R
        add(HardCase(
            f"chatter-R{restitution:g}", "quasi-static forcing presses the absorber on the stop: Zeno chatter, sticking, release, every period", problem, _rest(), 30,
            per_engine(
                exact(sticking=True),
                integrated(impacts=rigid_impacts, times=times, sticking=True, note=note or "times to 1e-7 s (measured 2e-8 BDF, 4e-8 Radau)"),
                integrated(impacts=rigid_impacts, times=times, sticking=True, note=note or "times to 1e-7 s (measured 4e-8 Radau)"),
                NotRun("R = 0 needs an infinitely damped bumper") if restitution == 0.0 else Expect(  # exact: the table's input R
                    impacts="free", x1=1e-4,
                    note="a bumper has no sticking: a few resolved bounces, then a long pressed contact (64 contacts against 194 impacts); |X1| to 1e-4 (measured 7e-6)",
                ),
            ),
        ))

    undamped = ImpactProblem(UNDAMPED, RigidStop(2e-3, 1.0), HarmonicForce(PAPER_AMPLITUDE, 25.0))
    add(HardCase(
        "elastic-undamped", "R = 1 and B1 = B2 = 0: nothing dissipates, energy changes by the input work only", undamped, _rest(), 30,
        per_engine(
            exact(), integrated(states=5e-6, note="strobe states to 5e-6 (measured 4e-7 BDF)"), integrated(states=5e-6),
            Expect(impacts="free", x1=0.1, restitution=1e-3, note="undamped quasi-periodic motion: contacts of finite duration change the sequence (30 against 28); |X1| to 10 % (3.7 %); R(0) = 1 to 5e-5"),
        ),
        bumper=KelvinVoigtBumper(undamped.clearance, BUMPER_FREQUENCY, 0.0),
    ))

    zero = ImpactProblem(PAPER_SYSTEM, RigidStop(0.0, 0.5), HarmonicForce(PAPER_AMPLITUDE, 25.0))
    add(HardCase(
        "zero-clearance", "Delta = 0: the stop at the static equilibrium, the start at rest on it", zero, _rest(), 40,
        per_engine(
            exact(sticking=True), integrated(sticking=True), integrated(sticking=True),
            Expect(impacts="at_least", x1=0.03, restitution=0.01, note="starts in contact at rest on the bumper, counted as one more contact; |X1| to 3 % (1.3 %)"),
        ),
    ))

    far = ImpactProblem(PAPER_SYSTEM, RigidStop(1.0, 0.2), HarmonicForce(PAPER_AMPLITUDE, 23.0))
    add(HardCase(
        "far-clearance", "the stop 1 m away (300x the motion): no contact, the linear steady state", far, _linear(far), 50,
        per_engine(exact(impacts="none", reference=1e-12), integrated(impacts="none", reference=1e-5), integrated(impacts="none", reference=1e-5), Expect(impacts="none", reference=1e-5)),
        reference="linear",
    ))

    # bumpers: the compliant engine against exact at the R of one collision
    problem, start = _pgf(25.0, 0.2)
    add(HardCase(
        "stiff-bumper-20kHz", "a 20 kHz bumper, 550x the system's fastest mode: stiff contact equations", problem, start, 40,
        per_engine(
            exact(), NotRun(BUMPER_ONLY), NotRun(BUMPER_ONLY),
            Expect(times=1e-5, x1=2e-3, restitution=1e-3, impulse=2e-3, note="|X1| converges like 1 / Omega_b: 0.6 % at 4 kHz, so 0.12 % here (measured), bound 0.2 %"),
        ),
        bumper=matching_bumper(problem, 20_000.0),
    ))
    problem, start = _pgf(25.0, restitution_from_loss_factor(OVERDAMPED))
    add(HardCase(
        "overdamped-bumper", "bumper loss factor 2 (overdamped, R = 0.048): no oscillation in the contact", problem, start, 40,
        per_engine(
            exact(), NotRun(BUMPER_ONLY), NotRun(BUMPER_ONLY),
            Expect(times=1e-4, x1=5e-3, restitution=2e-3, impulse=5e-3, note="5 kHz: |X1| to 0.5 % (measured 0.16 %), onsets to 1e-4 s (1.5e-5)"),
        ),
        bumper=KelvinVoigtBumper(problem.clearance, BUMPER_FREQUENCY, OVERDAMPED),
    ))

    # resonances
    problem, start = _pgf(RESONANCES[0], 0.2)
    add(HardCase(
        "resonance-1", "exactly at the first linear resonance (23.02 Hz), where the paper's chi22'(0-) gives a spike", problem, start, 40,
        per_engine(
            exact(reference=1e-10), integrated(reference=1e-7), integrated(reference=1e-7),
            Expect(x1=1e-2, reference=1e-2, note="5 kHz: |X1| to 1 % (measured 0.5 %), impulse to 1 % of PGF's (0.4 %)"),
        ),
        reference="pgf",
    ))
    problem = ImpactProblem(PAPER_SYSTEM, RigidStop(PAPER_CLEARANCE, 0.2), HarmonicForce(PAPER_AMPLITUDE, RESONANCES[1]))
    add(HardCase(
        "resonance-2", "exactly at the second linear resonance (36.07 Hz): no stable one-impact orbit, irregular impacts", problem, _rest(), 20,
        per_engine(exact(), integrated(), integrated(), Expect(times=1e-3, x1=0.03, note="5 kHz, from rest: onsets to 1e-3 s (1.2e-4), |X1| to 3 % (0.85 %)")),
    ))
    problem = ImpactProblem(PAPER_SYSTEM, RigidStop(PAPER_CLEARANCE, 0.2), HarmonicForce(PAPER_AMPLITUDE, ANTIRESONANCE))
    antiresonance_note = "X1's amplitude vanishes at the anti-resonance: strobe states and |X1| are compared to that tiny amplitude (measured 1e-4 and 1.3e-6, BDF)"
    add(HardCase(
        "antiresonance-no-contact", "exactly at the anti-resonance (33.00 Hz): primary mass nearly still, absorber swings 2.3 mm < Delta", problem, _linear(problem), 40,
        per_engine(
            exact(impacts="none", reference=1e-11), integrated(impacts="none", states=1e-3, x1=1e-4, reference=1e-3, note=antiresonance_note),
            integrated(impacts="none", states=1e-3, x1=1e-4, reference=1e-3, note=antiresonance_note), Expect(impacts="none", reference=1e-3),
        ),
        reference="linear",
    ))
    problem = ImpactProblem(PAPER_SYSTEM, RigidStop(2e-3, 0.2), HarmonicForce(PAPER_AMPLITUDE, ANTIRESONANCE))
    add(HardCase(
        "antiresonance-contact", "at the anti-resonance with Delta = 2 mm: impacts on a nearly still primary mass", problem, _rest(), 30,
        per_engine(
            exact(), integrated(states=1e-5, x1=1e-5, note="X1 is small here: strobe states and |X1| to 1e-5 (measured 4e-7, 1e-7 BDF)"), integrated(states=1e-5, x1=1e-5),
            Expect(x1=0.1, note="the last 10 of 30 periods from rest are still transient: |X1| to 10 % (measured 4 %)"),
        ),
    ))

    # amplitude extremes
    paper = ImpactProblem(PAPER_SYSTEM, RigidStop(PAPER_CLEARANCE, 0.2), HarmonicForce(PAPER_AMPLITUDE, 25.0))
    tiny = ImpactProblem(PAPER_SYSTEM, RigidStop(PAPER_CLEARANCE * TINY, 0.2), HarmonicForce(PAPER_AMPLITUDE * TINY, 25.0))
    atol_note = (
        "atol 1e-14 m is 3e-5 of this 0.3 nm motion: errors ~100x those at the paper's scale (measured: times 3e-7 s, "
        "states 1e-4, energy 3e-5, BDF; its exact flow passes the stop by up to 1e-5 of the length scale); a user must "
        "scale atol with the motion"
    )
    add(HardCase(
        "tiny-amplitude", "q = 1 uN, Delta = 0.3 nm: the paper's case scaled by 1e-7 (the motion is exactly scaled)", tiny, _rest(), 25,
        per_engine(
            exact(reference=1e-12),
            integrated(times=3e-6, states=1e-3, x1=1e-4, energy=1e-3, penetration=1e-4, reference=1e-3, note=atol_note),
            integrated(times=3e-6, states=1e-3, x1=1e-4, energy=1e-3, penetration=1e-4, reference=1e-3, note=atol_note),
            Expect(x1=2e-2, note="5 kHz: |X1| to 2 % (measured 0.5 %)"),
        ),
        reference="scaled",
        scaled_from=(paper, TINY),
    ))
    huge = ImpactProblem(PAPER_SYSTEM, RigidStop(PAPER_CLEARANCE, 0.2), HarmonicForce(PAPER_AMPLITUDE * HUGE, 25.0))
    add(HardCase(
        "huge-amplitude", "q = 10 kN: motion 1000x the clearance, chatter and sticking every period", huge, _rest(), 10,
        per_engine(
            exact(sticking=True), integrated(sticking=True), integrated(sticking=True),
            Expect(impacts="free", x1=1e-2, restitution=0.02, note="chatter sequences become pressed contacts (36 contacts against 97 impacts); |X1| to 1 % (measured 0.1 %)"),
        ),
    ))

    # edges of the stable one-impact band at R = 0.2 (Floquet modulus 0.998 and 0.974)
    for frequency, bumper, compliant in (
        (21.21, None, Expect(x1=1e-2, reference=0.03, note="5 kHz: |X1| to 1 % (measured 0.36 %), impulse to 3 % of PGF's (1.4 %)")),
        (26.70, 20_000.0, Expect(x1=0.05, note=(
            "the saddle-node at the band's top moves with the bumper's stiffness: with 5 kHz the orbit is gone (57 contacts in 60 periods, |X1| 30 % off); "
            "with 20 kHz it stays, |X1| to 5 % (measured 1.9 %; 0.7 % at 50 kHz)"))),
    ):
        problem, start = _pgf(frequency, 0.2)
        add(HardCase(
            f"band-edge-{frequency:g}Hz", "edge of the stable one-impact band: a Floquet multiplier near 1", problem, start, 60,
            per_engine(exact(reference=1e-11), integrated(reference=1e-6), integrated(reference=1e-6), compliant),
            reference="pgf",
            bumper=None if bumper is None else matching_bumper(problem, bumper),
        ))

    # long runs: no drift in the impact count, no cost growing with the run (event records, see NOTES)
    problem = ImpactProblem(PAPER_SYSTEM, RigidStop(PAPER_CLEARANCE, 0.2), HarmonicForce(PAPER_AMPLITUDE, 25.0))
    long_compliant = Expect(times=1e-4, x1=1e-2, restitution=0.01, note="5 kHz: onsets to 1e-4 s (measured 2.4e-5), |X1| to 1 % (0.5 %)")
    add(HardCase(
        "long-500-periods", "20 s from rest, 500 impacts", problem, _rest(), 500,
        per_engine(exact(), integrated(), integrated(), long_compliant, radau=NotRun(RADAU_COST)),
        timeout=120, long=True,
    ))
    add(HardCase(
        "very-long-10000-periods", "400 s from rest, 10 000 impacts", problem, _rest(), 10_000,
        per_engine(
            exact(penetration=1e-10, note="at t = 400 s the round-off of w t alone is ~1e-11 of the motion: its flow is checked to 1e-10 (passes at 1e-11, not at 1e-12)"),
            integrated(times=1e-7), integrated(times=1e-7), long_compliant, radau=NotRun(RADAU_COST),
        ),
        timeout=900, slow=True,
    ))
    chatter = ImpactProblem(PAPER_SYSTEM, RigidStop(1e-4, 0.05), HarmonicForce(PAPER_AMPLITUDE, 10.0))
    add(HardCase(
        "very-long-chatter", "100 s of chatter, sticking and release (1000 periods)", chatter, _rest(), 1000,
        per_engine(
            exact(sticking=True), integrated(impacts="free", times=None, sticking=True, note=chatter_note),
            integrated(impacts="free", times=None, sticking=True, note=chatter_note),
            Expect(impacts="free", x1=1e-4, note="a bumper has no sticking (see chatter-R0.05)"), radau=NotRun(RADAU_COST),
        ),
        timeout=900, slow=True,
    ))
    return cases


CASES = _cases()
