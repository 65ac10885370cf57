"""The example of docs/python.md runs as written, from the source tree, and prints what the page says."""
import os
import re
import subprocess
import sys

from conftest import SOURCE_DIR


def page_block(name, language):
    text = (SOURCE_DIR / "docs" / "python.md").read_text()
    block = re.search(rf"<!-- {name}:begin -->\n```{language}\n(.*?)```\n<!-- {name}:end -->", text, re.S)
    assert block, f"docs/python.md: no {name} block"
    return block.group(1), text[block.end():]


def test_the_python_example_of_the_docs_runs_and_prints_what_the_page_shows():
    code, after = page_block("python-example", "python")
    assert 18 <= len([line for line in code.splitlines() if line.strip()]) <= 22  # a 20-line example
    shown = re.search(r"prints\n\n```\n(.*?)```", after, re.S).group(1)
    p = subprocess.run([sys.executable, "-c", code], cwd=SOURCE_DIR, capture_output=True, text=True,
                       timeout=300, env=dict(os.environ))
    assert p.returncode == 0, p.stderr
    assert p.stdout == shown
