"""A design study's answer as values (:func:`design_answer`): the design to build, each compared design's worst case
and operating value, the certificates, the warnings and the page's own answer sentence, read from the dataset as the
page reads them, so that a script, a notebook and the page say the same. In Jupyter a :class:`DesignAnswer` shows
itself as the page's answer; :meth:`DesignAnswer.to_dataframe` gives every evaluated candidate as a table.

Example::

    from vibroimpact import design_answer, load_scene, run_study

    answer = design_answer(run_study(load_scene("design_rigid_stop")))
    print(answer.headline)
    build = answer.recommended.variables        # {"clearance": 0.003344, "restitution": 0.1681}
"""

from __future__ import annotations

import html
import math
from dataclasses import dataclass, field
from typing import Any, Mapping

import xarray as xr

from vibroimpact.kinds.design.answer import DESIGN_TITLES, answer_text, certified_worst, design_text, design_worst, present_designs, sample_name, variable_names, warnings
from vibroimpact.kinds.design.scene import safe_name
from vibroimpact.model.keywords import suggest_keywords

__all__ = ["ComparedDesign", "Certificate", "DesignAnswer", "design_answer"]


@dataclass(frozen=True)
class ComparedDesign:
    """One design the page compares.

    Attributes
    ----------
    title : str
        ``recommended design``, ``the scene's design`` or ``best linear absorber``.
    variables : Mapping of str to float
        Its design variables [their units: the dataset's ``design_<name>``]; empty for the linear absorber.
    description : str
        As the page writes it (``Delta = 3.344 mm, R = 0.1681``; ``no stop, k2 = 2061 N/m, b2 = 5.337 N s/m``).
    worst_case : float
        Its worst case over the band and the tolerance box [the objective's unit]: the largest of the screened
        samples, its certificates and (the recommended design) the box's worst point; NaN where it has none.
    certified_worst_case : float
        The largest of its certificates' worst cases (NaN: not certified).
    operating : float
        The worst coexisting value at the operating frequency [the constraint's unit] (NaN: no constraint).
    """

    title: str
    variables: Mapping[str, float]
    description: str
    worst_case: float
    certified_worst_case: float
    operating: float


@dataclass(frozen=True)
class Certificate:
    """One certified candidate under one mistuning.

    Attributes
    ----------
    evaluation : int
        The certified candidate (its row in :meth:`DesignAnswer.to_dataframe`).
    sample : str
        Which mistuning (``sample 3``, ``the tolerance box's worst point``).
    worst_case, screened : float
        The certified largest stable value over the band, and the closed-form screen's [the objective's unit].
    frequency : float
        Where the certified worst case is [Hz].
    motion : str
        The motion that sets it.
    operating : float
        The largest value at the operating frequency over every motion found there [the constraint's unit].
    error : str
        Why the certification failed (empty: it did not).
    """

    evaluation: int
    sample: str
    worst_case: float
    screened: float
    frequency: float
    motion: str
    operating: float
    error: str


@suggest_keywords
@dataclass(frozen=True)
class DesignAnswer:
    """What a design study answers (:func:`design_answer`).

    Attributes
    ----------
    headline : str
        The page's answer sentence (``Build Delta = ... : worst case |X1| = ... over ... Hz and ...``).
    warnings : tuple of str
        What the page says before any figure (a variable on its bound, a certificate above the screen, ...).
    objective, unit : str
        What is minimised (``x1_amplitude``) and its unit (``m`` or ``N``).
    designs : tuple of ComparedDesign
        The compared designs the dataset has, recommended first.
    certificates : tuple of Certificate
        Every certification, in the dataset's order.
    dataset : xarray.Dataset
        The study's dataset the answer was read from.
    """

    headline: str
    warnings: tuple[str, ...]
    objective: str
    unit: str
    designs: tuple[ComparedDesign, ...]
    certificates: tuple[Certificate, ...]
    dataset: xr.Dataset = field(repr=False, compare=False)

    @property
    def recommended(self) -> ComparedDesign | None:
        """The recommended design (None: the study recommended none)."""
        return next((design for design in self.designs if design.title == DESIGN_TITLES[0] and design.variables), None)

    def to_dataframe(self) -> Any:
        """Every evaluated candidate, a row each (``evaluation``): its variables, score, screened worst case and
        stage (pandas.DataFrame)."""
        return self.dataset[[name for name, variable in self.dataset.data_vars.items() if variable.dims == ("evaluation",)]].to_dataframe()

    def __str__(self) -> str:
        return "\n".join([self.headline, *(f"warning: {line}" for line in self.warnings)])

    def _repr_html_(self) -> str:
        """The answer as a notebook shows it: the sentence, the warnings, then the compared designs."""
        rows = "".join(f"<tr><td>{html.escape(d.title)}</td><td>{html.escape(d.description)}</td><td>{_number(d.worst_case)}</td>"
                       f"<td>{_number(d.operating)}</td></tr>" for d in self.designs)
        warned = "".join(f"<li>{html.escape(line)}</li>" for line in self.warnings)
        return (f"<p><b>{html.escape(self.headline)}</b></p>" + (f"<ul>{warned}</ul>" if warned else "")
                + f"<table><tr><th>design</th><th>values</th><th>worst case [{html.escape(self.unit)}]</th><th>at the operating point</th></tr>{rows}</table>")


def _number(value: float) -> str:
    return "-" if not math.isfinite(value) else f"{value:.4g}"


@suggest_keywords
def design_answer(dataset: xr.Dataset) -> DesignAnswer:
    """The answer of a design study's dataset (from :func:`~vibroimpact.runs.run.run_study` or read back by
    :func:`~vibroimpact.runs.run.read_dataset`): the same sentence, numbers and warnings the page shows; ValueError
    for a dataset of another kind."""
    if "design_sample_value" not in dataset or "certificate_worst" not in dataset:
        raise ValueError(f"design_answer: not a design study's dataset (kind {dataset.attrs.get('study_kind', '?')!r}); run a scene with a 'design' section")
    names = variable_names(dataset)
    designs = []
    for k in present_designs(dataset):
        title = DESIGN_TITLES[k]
        values = {name: float(dataset[f"design_{safe_name(name)}"].values[k]) for name in names}
        variables = {name: value for name, value in values.items() if math.isfinite(value)}
        operating = float(dataset["design_operating_amplitude"].values[k]) if "design_operating_amplitude" in dataset else math.nan
        designs.append(ComparedDesign(title, variables, design_text(dataset, k), design_worst(dataset, k), certified_worst(dataset, k)[0], operating))
    certificates = tuple(
        Certificate(int(dataset["certificate_evaluation"].values[r]), sample_name(int(dataset["certificate_sample"].values[r])), float(dataset["certificate_worst"].values[r]),
                    float(dataset["certificate_screened"].values[r]), float(dataset["certificate_frequency"].values[r]), str(dataset["certificate_motion"].values[r]),
                    float(dataset["certificate_operating_worst"].values[r]) if "certificate_operating_worst" in dataset else math.nan, str(dataset["certificate_error"].values[r]))
        for r in range(dataset.sizes.get("certificate", 0)))  # fmt: skip
    unit = str(dataset["design_sample_value"].attrs.get("units", ""))
    objective = str(dataset.attrs.get("objective", ""))
    return DesignAnswer(answer_text(dataset), tuple(warnings(dataset)), objective, unit, tuple(designs), certificates, dataset)
