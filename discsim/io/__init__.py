"""Files: the checksummed container format (:mod:`.container`), checkpoints of every engine in both
directions (:mod:`.checkpoints`) and streamed event logs (:mod:`.streams`)."""
