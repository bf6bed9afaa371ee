"""Running engines: the one driver (:mod:`.driver`) and its observers (:mod:`.observers`)."""
