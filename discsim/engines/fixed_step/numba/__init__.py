"""The compiled frame of the fixed-step engine (numba, from the ``fast`` extra).

:mod:`~discsim.engines.fixed_step.numba.kernels` (``resolve``, ``revert``, ``separate``) and
:mod:`~discsim.engines.fixed_step.numba.sub_frame` (``bisect``, ``swept``, over its parts in
:mod:`~discsim.engines.fixed_step.numba.detection`, :mod:`~discsim.engines.fixed_step.numba.candidates` and
:mod:`~discsim.engines.fixed_step.numba.cell_table`) hold the ``njit`` functions on plain arrays;
:class:`~discsim.engines.fixed_step.numba.policy.CompiledFrame` and
:class:`~discsim.engines.fixed_step.numba.policy.CompiledSubFrame` are the policies the engine hands its
frames to when ``backend="numba"``. Neither is imported by ``import discsim``: the engine imports them when a
compiled frame is asked for, so that importing discsim stays fast and works without numba.
"""
