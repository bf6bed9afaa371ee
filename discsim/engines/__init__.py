"""The engines: :mod:`.event_driven` (PIC, exact) and :mod:`.fixed_step` (PIT), both meeting the protocol
of :mod:`.base`."""
