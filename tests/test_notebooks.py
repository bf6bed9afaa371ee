"""Every notebook in ``notebooks/`` runs top to bottom without an error, and is committed without outputs.

Execution uses nbclient with a Jupyter kernel named ``python3``. Which interpreter that name starts is
decided by kernel specs found on disk (``~/.local/share/jupyter/kernels``, ``<prefix>/share/jupyter``,
``JUPYTER_PATH``...), so a spec left by another Python (a stale ``ipykernel install --user``, say) could run
the notebooks against a different interpreter, with another discsim or none at all. To make the test
independent of what is installed where, it writes its own ``python3`` kernel spec into a temporary
directory, whose command is ``sys.executable -m ipykernel_launcher``, and hands nbclient a
``KernelManager`` whose spec manager looks only in that directory. The kernel is then always the very
interpreter running pytest (the fresh venv of ``.ci/run``). The kernel also gets the directory holding
the ``discsim`` package this test imported at the front of ``PYTHONPATH``, so that the notebooks exercise
the very discsim under test even when another copy is installed in that interpreter. A last cell, added
in memory, prints the kernel's interpreter and discsim, and the test checks both.
"""

import json
import os
import sys
import time
from pathlib import Path

import pytest
from paths import NOTEBOOKS

import discsim

NOTEBOOKS_DIR = NOTEBOOKS
NOTEBOOKS = sorted(NOTEBOOKS_DIR.glob("*.ipynb"))
#: Seconds any one cell may take before the run fails (whole notebooks take 1-2 minutes).
CELL_TIMEOUT = 600

_PROBE = "import sys as _sys, discsim as _ds\nprint(_sys.executable)\nprint(_ds.__file__)"


@pytest.fixture(scope="module")
def kernel_spec_dir(tmp_path_factory):
    """A directory holding one kernel spec, ``python3``, that runs this interpreter."""
    pytest.importorskip("ipykernel")
    kernels = tmp_path_factory.mktemp("kernels")
    spec = kernels / "python3"
    spec.mkdir()
    argv = [sys.executable, "-m", "ipykernel_launcher", "-f", "{connection_file}"]
    (spec / "kernel.json").write_text(json.dumps({"argv": argv, "display_name": "Python 3", "language": "python"}))
    return kernels


def _kernel_manager(kernel_spec_dir):
    from jupyter_client.kernelspec import KernelSpecManager
    from jupyter_client.manager import KernelManager

    specs = KernelSpecManager(kernel_dirs=[str(kernel_spec_dir)])
    km = KernelManager(kernel_name="python3", kernel_spec_manager=specs)
    assert km.kernel_spec.argv[0] == sys.executable, km.kernel_spec.argv
    return km


def test_there_are_notebooks():
    names = [p.name for p in NOTEBOOKS]
    assert names[:4] == [
        "01_pit_vs_pic.ipynb",
        "02_trajectories.ipynb",
        "03_when_is_pit_good_enough.ipynb",
        "04_physics.ipynb",
    ], names


@pytest.mark.parametrize("path", NOTEBOOKS, ids=[p.stem for p in NOTEBOOKS])
def test_notebook_is_committed_without_outputs(path):
    nbformat = pytest.importorskip("nbformat")
    nb = nbformat.read(path, as_version=4)
    nbformat.validate(nb)
    for k, cell in enumerate(nb.cells):
        if cell.cell_type == "code":
            assert cell.outputs == [], f"{path.name}: cell {k} has outputs; clear them before committing"
            assert cell.execution_count is None, f"{path.name}: cell {k} has an execution count"


@pytest.mark.slow
@pytest.mark.parametrize("path", NOTEBOOKS, ids=[p.stem for p in NOTEBOOKS])
def test_notebook_runs_top_to_bottom(path, kernel_spec_dir):
    nbformat = pytest.importorskip("nbformat")
    nbclient = pytest.importorskip("nbclient")
    nb = nbformat.read(path, as_version=4)
    nb.cells.append(nbformat.v4.new_code_cell(_PROBE))
    km = _kernel_manager(kernel_spec_dir)
    client = nbclient.NotebookClient(
        nb,
        km=km,
        kernel_name="python3",
        timeout=CELL_TIMEOUT,
        resources={"metadata": {"path": str(NOTEBOOKS_DIR)}},  # the kernel's working directory
    )
    package_root = str(Path(discsim.__file__).resolve().parent.parent)
    pythonpath = os.pathsep.join(p for p in (package_root, os.environ.get("PYTHONPATH", "")) if p)
    env = dict(os.environ, MPLBACKEND="Agg", PYTHONPATH=pythonpath)
    start = time.perf_counter()
    try:
        # Raises CellExecutionError, with the traceback, if any cell fails. nbclient keeps a kernel it
        # did not start alive unless told otherwise (cleanup_kc), so the finally is belt and braces.
        client.execute(env=env, cleanup_kc=True)
    finally:
        if km.has_kernel:
            km.shutdown_kernel(now=True)
    elapsed = time.perf_counter() - start
    print(f"{path.name}: {elapsed:.0f} s")

    probe = "".join(o.get("text", "") for o in nb.cells[-1].outputs if o.output_type == "stream").splitlines()
    assert probe[0] == sys.executable, probe  # the kernel ran this interpreter...
    assert Path(probe[1]).resolve() == Path(discsim.__file__).resolve(), probe  # ...and this discsim
    errors = [o for cell in nb.cells if cell.cell_type == "code" for o in cell.outputs if o.output_type == "error"]
    assert not errors
