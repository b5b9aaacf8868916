"""The example notebook (docs/notebooks/dc_motor.ipynb) executes from top to bottom."""

from __future__ import annotations

import json
import sys
from pathlib import Path

import pytest

NOTEBOOK = Path(__file__).resolve().parents[2] / "docs" / "notebooks" / "dc_motor.ipynb"


def test_dc_motor_notebook_executes(tmp_path, monkeypatch):
    nbformat = pytest.importorskip("nbformat")
    nbclient = pytest.importorskip("nbclient")
    pytest.importorskip("ipykernel")
    nb = nbformat.read(NOTEBOOK, as_version=4)
    assert not any(c.get("outputs") for c in nb.cells if c.cell_type == "code"), \
        "commit the notebook without outputs"
    # a kernel of this very interpreter, found before any other "python3" kernel spec
    spec = tmp_path / "jupyter" / "kernels" / "bgmodelica-test"
    spec.mkdir(parents=True)
    (spec / "kernel.json").write_text(json.dumps({
        "argv": [sys.executable, "-m", "ipykernel_launcher", "-f", "{connection_file}"],
        "display_name": "bgmodelica tests", "language": "python"}))
    monkeypatch.setenv("JUPYTER_PATH", str(tmp_path / "jupyter"))
    monkeypatch.setenv("MPLBACKEND", "module://matplotlib_inline.backend_inline")
    client = nbclient.NotebookClient(nb, timeout=180, kernel_name="bgmodelica-test",
                                     resources={"metadata": {"path": str(tmp_path)}})
    client.execute()                      # raises CellExecutionError naming the cell
    outputs = [o for c in nb.cells if c.cell_type == "code" for o in c.outputs]
    assert not [o for o in outputs if o.output_type == "error"]
    html = [o["data"]["text/html"] for o in outputs if "text/html" in o.get("data", {})]
    assert any("balanced" in h and "resistor.R" in h for h in html)       # the model
    assert any("structural index" in h for h in html)                    # compiled model
    assert any("<img" in h and "rotor.w" in h for h in html)             # result
    assert any("<svg" in h for h in html)                                # bond graph
    images = [o for o in outputs if "image/png" in o.get("data", {})]
    assert len(images) >= 2                                              # the plots
    text = "".join(o.get("text", "") for o in outputs if o.output_type == "stream")
    assert "analytic 109.09" in text and "steady state" in text
