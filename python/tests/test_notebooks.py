"""Every example notebook runs from start to end (nbclient) against the shaker program under
test, in its own folder, with the package as pip installs it; a failing cell fails the test.
Each notebook ends by asserting a physical number (mass conservation, profiles against
fields, centre of mass above the plate)."""
import glob
import os
import shutil
import tempfile

import nbformat
import pytest
from nbclient import NotebookClient

from package_install import environment_with, install_package

EXAMPLES = os.path.join(os.path.dirname(os.path.abspath(__file__)), os.pardir, "examples")
NOTEBOOKS = sorted(glob.glob(os.path.join(EXAMPLES, "*.ipynb")))


def test_three_notebooks_kept_without_outputs():
    assert [os.path.basename(p) for p in NOTEBOOKS] == [
        "base_case_md.ipynb", "continuum_3d_fields.ipynb", "md_against_continuum.ipynb"]
    for path in NOTEBOOKS:
        notebook = nbformat.read(path, as_version=4)
        nbformat.validate(notebook)
        code = [cell for cell in notebook.cells if cell.cell_type == "code"]
        assert all(not cell.outputs and cell.execution_count is None for cell in code), path
        assert "assert " in code[-1].source, f"{path}: the last cell asserts nothing"


@pytest.fixture(scope="module")
def installed():
    folder = tempfile.mkdtemp(prefix="shaker-pytest-notebooks-install-")
    yield install_package(folder)
    shutil.rmtree(folder, ignore_errors=True)


@pytest.mark.parametrize("path", NOTEBOOKS, ids=os.path.basename)
def test_notebook_runs(path, shaker, installed, work_dir, monkeypatch):
    # The kernel inherits this environment: the installed package only, the program, one
    # thread, and no warning from the debugger ipykernel loads.
    environment = environment_with(installed, SHAKER=shaker, OMP_NUM_THREADS="1",
                                   PYDEVD_DISABLE_FILE_VALIDATION="1")
    for key, value in environment.items():
        monkeypatch.setenv(key, value)
    notebook = nbformat.read(path, as_version=4)
    NotebookClient(notebook, timeout=300, kernel_name="python3",
                   resources={"metadata": {"path": work_dir}}).execute()
    outputs = [o for cell in notebook.cells if cell.cell_type == "code" for o in cell.outputs]
    assert not [o for o in outputs if o.output_type == "error"]
    figures = [o for o in outputs if "image/png" in o.get("data", {})]
    assert figures, "no figure was drawn"
    # The last cell prints the number it asserts.
    print(f"{os.path.basename(path)}: {len(figures)} figures; last cell printed: "
          + "".join(o.get("text", "") for o in notebook.cells[-1].outputs).strip())
