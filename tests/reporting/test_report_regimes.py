"""Regime maps give every flag a colour of its own, and the legend says which."""

from __future__ import annotations

import itertools

import matplotlib.pyplot as plt
import numpy as np
import xarray as xr
from matplotlib.collections import QuadMesh
from matplotlib.colors import to_rgb, to_rgba

from vibroimpact.analysis.stability import Regime
from vibroimpact.kinds.stepped.responses import regime_figure
from vibroimpact.reporting.style import REGIME_COLOURS, regime_label

from tests.reporting.test_report_support import steady_dataset

#: Smallest RGB distance between two flags' colours (0..sqrt 3): tells them apart on screen.
DISTINCT = 0.15


def test_every_flag_has_a_colour_of_its_own() -> None:
    assert set(REGIME_COLOURS) == set(Regime)
    for (a, colour_a), (b, colour_b) in itertools.combinations(REGIME_COLOURS.items(), 2):
        distance = float(np.linalg.norm(np.subtract(to_rgb(colour_a), to_rgb(colour_b))))
        assert distance > DISTINCT, f"{a.name} and {b.name}: {colour_a} and {colour_b}"


#: Colour-vision deficiencies simulated on linear RGB (Machado, Oliveira & Fernandes 2009, severity 1).
_DEFICIENCIES = {
    "protanopia": ((0.152286, 1.052583, -0.204868), (0.114503, 0.786281, 0.099216), (-0.003882, -0.048116, 1.051998)),
    "deuteranopia": ((0.367322, 0.860646, -0.227968), (0.280085, 0.672501, 0.047413), (-0.011820, 0.042940, 0.968881)),
    "tritanopia": ((1.255528, -0.076749, -0.178779), (-0.078411, 0.930809, 0.147602), (0.004733, 0.691367, 0.303900)),
}
#: Smallest CIELAB difference (CIE76) between two flags' colours as a colour-blind reader sees them.
CVD_DISTINCT = 10.0


def _lab(colour: str, deficiency: str | None) -> np.ndarray:
    """CIELAB (D65) of sRGB ``colour`` as seen with ``deficiency`` (None: normal vision)."""
    rgb = np.asarray(to_rgb(colour))
    linear = np.where(rgb <= 0.04045, rgb / 12.92, ((rgb + 0.055) / 1.055) ** 2.4)
    if deficiency is not None:
        linear = np.clip(np.asarray(_DEFICIENCIES[deficiency]) @ linear, 0.0, 1.0)
    xyz = np.array([[0.4124, 0.3576, 0.1805], [0.2126, 0.7152, 0.0722], [0.0193, 0.1192, 0.9505]]) @ linear / np.array([0.95047, 1.0, 1.08883])
    f = np.where(xyz > 216 / 24389, np.cbrt(xyz), (24389 / 27 * xyz + 16) / 116)
    return np.array([116 * f[1] - 16, 500 * (f[0] - f[1]), 200 * (f[1] - f[2])])


def test_regime_colours_stay_distinct_for_colour_blind_readers() -> None:
    """No two flags differ by red against green alone: under simulated protanopia, deuteranopia and tritanopia every
    pair stays at least CVD_DISTINCT apart (the former palette had pairs 4 apart: green and red, blue and lilac)."""
    for deficiency in (None, *_DEFICIENCIES):
        for (a, colour_a), (b, colour_b) in itertools.combinations(REGIME_COLOURS.items(), 2):
            difference = float(np.linalg.norm(_lab(colour_a, deficiency) - _lab(colour_b, deficiency)))
            assert difference > CVD_DISTINCT, f"{deficiency}: {a.name} {colour_a} and {b.name} {colour_b} differ by {difference:.1f}"


def _every_flag() -> xr.Dataset:
    """One solution whose regime runs through every flag along frequency at the first restitution ratio (the second
    is linear throughout, so that every column is drawn, ``not_computed`` included)."""
    ds = steady_dataset(engines=(), restitution=(0.2, 0.6), step=0.5).sel(solution=["pgf"])
    flags = np.empty((1, 2, ds.sizes["frequency"]), dtype=np.int8)
    flags[0, 0] = np.resize(np.array([int(r) for r in Regime]), ds.sizes["frequency"])
    flags[0, 1] = int(Regime.LINEAR)
    return ds.assign(regime=(("solution", "restitution", "frequency"), flags))


def test_drawn_map_gives_each_flag_one_colour_and_no_two_flags_the_same() -> None:
    ds = _every_flag()
    drawn = regime_figure(ds, "regime")
    drawn.figure.canvas.draw()
    meshes = [c for ax in drawn.figure.axes for c in ax.collections if isinstance(c, QuadMesh)]
    assert len(meshes) == 1
    flags = ds["regime"].values[0].ravel()  # every column computed: cells row by row, in frequency order
    colours = [tuple(np.round(c, 6)) for c in meshes[0].get_facecolors()]
    assert len(colours) == flags.size
    by_flag: dict[int, set[tuple[float, ...]]] = {}
    for flag, colour in zip(flags.tolist(), colours):
        by_flag.setdefault(flag, set()).add(colour)
    assert set(by_flag) == {int(r) for r in Regime}
    assert all(len(c) == 1 for c in by_flag.values()), by_flag
    assert len({next(iter(c)) for c in by_flag.values()}) == len(by_flag), "two flags share a colour"
    # the legend names each flag with the colour it is drawn in
    legend = drawn.figure.legends[0]
    entries = {text.get_text(): tuple(np.round(handle.get_facecolor(), 6)) for text, handle in zip(legend.get_texts(), legend.legend_handles)}
    for flag, colour in by_flag.items():
        assert entries[regime_label(Regime(flag))] == next(iter(colour))
        assert entries[regime_label(Regime(flag))] == tuple(np.round(to_rgba(REGIME_COLOURS[Regime(flag)]), 6))
    plt.close(drawn.figure)


def test_coarse_grid_blocks_reach_halfway_to_their_neighbours_only() -> None:
    """A simulation on 16-17 Hz (0.5 Hz steps) on a 15-20 Hz axis covers 15.75-17.25 Hz, not the whole axis."""
    from vibroimpact.grids.regime_map import block_edges

    f = np.linspace(15.0, 20.0, 101)
    np.testing.assert_allclose(block_edges(np.array([16.0, 16.5, 17.0]), f), [15.75, 16.25, 16.75, 17.25])
    np.testing.assert_allclose(block_edges(f, f)[[0, -1]], [15.0, 20.0])  # the fine grid fills the axis, no more
