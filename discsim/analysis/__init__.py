"""Analysis of finished runs: PIT against PIC (:mod:`.compare`), thermodynamics (:mod:`.thermo`) and
reference physics (:mod:`.theory`). Numpy in, numpy out; nothing here drives an engine."""
