"""What a page judges an absorber by, declared once for every kind: its operating point's tolerances.

An absorber exists for its notch: at its operating point (the anti-resonance of the linear absorber,
:meth:`vibroimpact.model.system.TwoDofSystem.antiresonance_frequency`, or a frequency the scene declares) the primary
mass barely moves. A stop that makes the response there worse than the same absorber without it has destroyed the
notch, whatever it does at the resonances. The stepped and design kinds' pages read these constants; neither copies
them.
"""

from __future__ import annotations

__all__ = ["WORSE_RATIO", "NEAREST"]

#: A stop makes the operating point worse where its value exceeds the linear absorber's by more than this factor [-]
#: (1 % above: beyond the round-off of a computed ratio, well below any change an engineer would accept).
WORSE_RATIO = 1.01
#: A computed grid frequency stands for the operating frequency only within this share of it [-] (the notch is narrow:
#: its width is of the order of the absorber's damping ratio times its frequency).
NEAREST = 0.01
