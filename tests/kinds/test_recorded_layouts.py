"""The design, concepts and validation kinds record the layout they ran as every other kind does
(:meth:`vibroimpact.model.layout.Layout.attributes`), and :meth:`~vibroimpact.model.layout.Layout.from_attributes`
reads it back: the structure, the load and (not for concepts, whose stops are each concept's) the stops."""

from __future__ import annotations

import numpy as np
import pytest
import xarray as xr

from vibroimpact.model.layout import Layout
from vibroimpact.scene import load_scene

from tests.golden.golden import SCENES


def _same_structure_and_load(recorded: Layout, layout: Layout) -> None:
    for name in ("mass_matrix", "stiffness_matrix", "damping_matrix"):
        np.testing.assert_allclose(getattr(recorded.structure, name), getattr(layout.structure, name), rtol=1e-15, atol=0.0)
    assert tuple(recorded.structure.coordinates) == tuple(layout.structure.coordinates)
    size = layout.structure.size
    np.testing.assert_allclose(recorded.load.weight_vector(size), layout.load.weight_vector(size), rtol=1e-15, atol=0.0)
    np.testing.assert_allclose(recorded.load.static_vector(size), layout.load.static_vector(size), rtol=1e-15, atol=0.0)


def _stops(layout: Layout) -> list[tuple[int, int | None, str, float | None]]:
    return [(spec.coordinate, spec.other, spec.side, spec.clearance) for spec in layout.stops]


@pytest.mark.parametrize("name", ["design_paper", "design_rigid_stop"])
def test_a_design_dataset_records_its_layout(name: str, monkeypatch: pytest.MonkeyPatch) -> None:
    """The run itself is stubbed (the golden suite holds its numbers): the attributes are the study's, not the run's."""
    from vibroimpact.kinds.design import study

    monkeypatch.setattr(study, "run_design", lambda scene, progress, runner: xr.Dataset(attrs={"objective": "x1_amplitude"}))
    scene = load_scene(SCENES / f"{name}.yaml")
    attrs = study.DesignStudy().run(scene, None, None).attrs  # type: ignore[arg-type]
    recorded = Layout.from_attributes(attrs)
    _same_structure_and_load(recorded, scene.layout)
    assert _stops(recorded) == [(1, None, "upper", scene.settings.clearance)]
    assert attrs["stop_layout"] == f"x2 <= {scene.settings.clearance * 1e3:g} mm, R = {scene.settings.restitution:g}"
    assert attrs["objective"] == "x1_amplitude" and attrs["system_m1"] == scene.layout.named_view().m1  # type: ignore[union-attr]


def test_a_concepts_dataset_records_the_shared_structure_and_load_but_no_stop(monkeypatch: pytest.MonkeyPatch) -> None:
    from vibroimpact.kinds.concepts import study

    monkeypatch.setattr(study, "run_concepts", lambda settings, progress, runner: xr.Dataset())
    scene = load_scene(SCENES / "absorber_concepts.yaml")
    attrs = study.ConceptsStudy().run(scene, None, None).attrs  # type: ignore[arg-type]
    assert not [key for key in attrs if key.startswith("stop_")]
    assert attrs["system_coordinates"] == "x1 x2" and attrs["excitation_kind"] == "force"
    assert (attrs["system_k2"], attrs["system_b2"]) == (4300.0, 0.08)  # the scene's own absorber, which the concepts vary
    np.testing.assert_array_equal(attrs["excitation_weights"], [1.0, 0.0])


@pytest.mark.parametrize(
    ("case", "stop", "layout"),
    [
        ("zeno", (0, None, "lower", 0.0), "z >= 0 mm, R = 0.5"),
        ("relative_stop", (1, 0, "upper", 0.003), "x2 - x1 <= 3 mm, R = 0.6"),
        ("budd_dux", (0, None, "upper", None), "x <= Delta, R = 0.8"),  # the continued clearances: swept
    ],
)
def test_a_validation_dataset_records_its_cases_layout(case: str, stop: tuple, layout: str) -> None:
    from vibroimpact.runs.run import run_study

    scene = load_scene(SCENES / f"validation_{case}.yaml")
    if case != "zeno":  # only the cheap case runs; the others' attributes are checked on an empty run
        from vibroimpact.kinds.validation import study

        with pytest.MonkeyPatch.context() as patch:
            patch.setattr(study, "run_validation", lambda settings, progress: xr.Dataset())
            attrs = study.ValidationStudy().run(scene, None, None).attrs  # type: ignore[arg-type]
    else:
        attrs = run_study(scene, progress=None).attrs
        assert attrs["validation_case"] == "zeno"
    recorded = Layout.from_attributes(attrs)
    _same_structure_and_load(recorded, scene.layout)
    assert _stops(recorded) == [stop] and attrs["stop_layout"] == layout
