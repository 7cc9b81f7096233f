"""The example notebook (docs/python-example.ipynb) runs from top to bottom."""

from pathlib import Path

from conftest import required

NOTEBOOK = Path(__file__).resolve().parents[3] / "docs" / "python-example.ipynb"


def test_the_example_notebook_executes(tmp_path):
    try:
        import nbclient
        import nbformat
    except ImportError:
        required("nbclient and nbformat", "pip install -r crates/python/tests/requirements.txt")
    notebook = nbformat.read(NOTEBOOK, as_version=4)
    client = nbclient.NotebookClient(
        notebook, timeout=600, kernel_name="python3", resources={"metadata": {"path": str(tmp_path)}}
    )
    client.execute()
    outputs = [o for cell in notebook.cells if cell.cell_type == "code" for o in cell.outputs]
    assert not [o for o in outputs if o.get("output_type") == "error"]
    assert (tmp_path / "scene.png").exists()
