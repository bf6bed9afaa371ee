"""Progress bars for long runs: :func:`~discsim._progress.progress_bar`, here where the run's observers look.

The bar itself lives on the ground floor (:mod:`discsim._progress`: the standard library, and tqdm when
installed), so that engines below ``run/`` (``compress(progress=True)``) can show one too.
"""

from discsim._progress import progress_bar

__all__ = ["progress_bar"]
