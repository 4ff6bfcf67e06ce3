"""Time-domain engines sharing one protocol (:class:`base.Engine`) and one trajectory type."""

from vibroimpact.engines.base import MODE_FREE, MODE_STUCK, Engine, EngineSettings, ImpactProblem, Trajectory
from vibroimpact.engines.exact import ExactEngine

__all__ = ["MODE_FREE", "MODE_STUCK", "Engine", "EngineSettings", "ExactEngine", "ImpactProblem", "Trajectory"]
