"""The README's Python example prints what the README says it prints."""

import subprocess
import sys
from pathlib import Path

README = Path(__file__).resolve().parents[3] / "README.md"
SECTION = "### Use specula from Python"


def example_and_output():
    """The first ```python block of the section and the ```text block after it."""
    text = README.read_text()
    section = text[text.index(SECTION):]
    code = section.split("```python\n", 1)[1].split("```", 1)[0]
    output = section.split("```text\n", 1)[1].split("```", 1)[0]
    return code, output


def test_the_readme_example_prints_its_output(tmp_path):
    code, output = example_and_output()
    assert len(code.strip().splitlines()) == 5
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                          cwd=tmp_path, check=True)
    assert done.stdout == output
