"""The fixed-step engine (PIT): the front class, its public state and its frame policies."""

from discsim.engines.fixed_step.engine import BROAD_PHASES, POLICIES, SUB_FRAME_POLICIES, FixedStep

__all__ = ["BROAD_PHASES", "POLICIES", "SUB_FRAME_POLICIES", "FixedStep"]
