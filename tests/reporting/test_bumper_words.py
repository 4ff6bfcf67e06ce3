"""A page states a bumper in the units its scene gave: K_b [N/m] and B_b [N s/m] with the Omega_b / 2 pi they mean,
or, as before, Omega_b / 2 pi [Hz] alone."""

from __future__ import annotations

import numpy as np
import xarray as xr

from vibroimpact.kinds.stepped.figures import where_text
from vibroimpact.kinds.swept.page import SweptSineRun
from vibroimpact.reporting.record import bumper_text

#: What a dataset of a scene with ``bumper: {stiffness: 1e5, damping: 20}`` on the paper's stop records.
PHYSICAL = {"stop_bumper_stiffness_N_per_m": 1e5, "stop_bumper_damping_N_s_per_m": 20.0}


def test_bumper_text_in_the_scenes_units() -> None:
    assert bumper_text({}, 250.0) == "bumper 250 Hz"
    assert bumper_text(PHYSICAL, 159.15494309189535) == "bumper K_b = 100000 N/m, B_b = 20 N s/m (Omega_b / 2 pi = 159.2 Hz)"
    loss_form = {"stop_bumper_stiffness_N_per_m": 1e5, "stop_bumper_damping_N_s_per_m": np.nan}
    assert bumper_text(loss_form, 159.15494309189535) == "bumper K_b = 100000 N/m (Omega_b / 2 pi = 159.2 Hz)"
    several = {"stop_bumper_stiffness_N_per_m": np.array([1e5, np.nan]), "stop_bumper_damping_N_s_per_m": np.array([20.0, np.nan])}
    assert bumper_text(several, 250.0) == "bumper 250 Hz"  # not every stop's: the stops' words say each


def test_figure_titles_and_sweep_captions_say_it() -> None:
    part = xr.Dataset(coords={"clearance": 0.003, "restitution": 0.2, "bumper_frequency": 159.15494309189535}, attrs=PHYSICAL)
    assert where_text(part) == "Delta = 3 mm, R = 0.2, bumper K_b = 100000 N/m, B_b = 20 N s/m (Omega_b / 2 pi = 159.2 Hz)"
    assert where_text(part.assign_attrs({key: np.nan for key in PHYSICAL})).endswith("bumper 159.155 Hz")
    run = SweptSineRun(15.0, 45.0, 0.1, 8, 159.15494309189535, 0.0316, bumper_text(PHYSICAL, 159.15494309189535))
    assert "bumper K_b = 100000 N/m, B_b = 20 N s/m (Omega_b / 2 pi = 159.2 Hz), xi_b = 0.0316" in run.text()
    assert "bumper 250 Hz, xi_b = 0.6500" in SweptSineRun(15.0, 45.0, 0.1, 8, 250.0, 0.65).text()
