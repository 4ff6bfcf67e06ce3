"""What every report page shares: the figure record and an atomic PNG writer (matplotlib without a display)."""

from __future__ import annotations

import io
from dataclasses import dataclass
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
from matplotlib.figure import Figure as MatplotlibFigure  # noqa: E402

from .atomic import atomic_path  # noqa: E402

__all__ = ["Figure", "save_figure"]


@dataclass(frozen=True)
class Figure:
    """A figure written to disk and its caption."""

    path: Path
    caption: str


def save_figure(fig: MatplotlibFigure, path: Path) -> Path:
    """Write ``fig`` as PNG to ``path`` atomically and close it."""
    buffer = io.BytesIO()
    fig.savefig(buffer, format="png", dpi=110, bbox_inches="tight")
    plt.close(fig)
    with atomic_path(path) as temporary:
        temporary.write_bytes(buffer.getvalue())
    return path
