"""The fixed-step engine (PIT): the front class, its public state, its broad phases and its policies."""

from discsim.engines.fixed_step.engine import BROAD_PHASES, POLICIES, SUB_FRAME_POLICIES, FixedStep
from discsim.engines.fixed_step.state import FixedStepState

__all__ = ["BROAD_PHASES", "POLICIES", "SUB_FRAME_POLICIES", "FixedStep", "FixedStepState"]
