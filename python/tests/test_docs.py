"""Every ```python block of docs/python.md runs, in order, in one namespace (as a reader would type
them into one session), from a folder that sees the source tree's; a line `expression  # -> text` also checks
that repr(expression) is `text`, so the numbers the page shows are the ones the code gives."""
import os
import re

import pytest

from conftest import ROOT

DOC = os.path.join(ROOT, "docs", "python.md")
CHECK = re.compile(r"^(?P<expr>[^#].*?)\s+# -> (?P<want>.+)$")


def blocks():
    text = open(DOC).read()
    return [(text[:m.start()].count("\n") + 2, m.group(1)) for m in re.finditer(r"```python\n(.*?)```", text, re.S)]


def checked_lines(code):
    """The block with each `expr  # -> want` line turned into an assertion on repr(expr)."""
    out = []
    for line in code.splitlines():
        m = CHECK.match(line)
        if m:
            out.append(f"__got = repr(({m['expr'].strip()})); assert __got == {m['want']!r}, "
                       f"'{{}} is {{}}, the doc says {{}}'.format({m['expr'].strip()!r}, __got, {m['want']!r})")
        else:
            out.append(line)
    return "\n".join(out)


def test_the_page_has_runnable_blocks_with_checks():
    found = blocks()
    assert len(found) >= 8
    assert sum(1 for _, code in found for line in code.splitlines() if CHECK.match(line)) >= 10


def test_every_python_block_runs(tmp_path, monkeypatch):
    # The source tree's folders seen from a scratch folder: relative names work as in the docs, and
    # what the blocks write (out/...) stays out of the tree.
    for name in ("scenes", "assets", "materials", "python", "docs"):
        os.symlink(os.path.join(ROOT, name), tmp_path / name)
    monkeypatch.chdir(tmp_path)
    namespace = {"__name__": "__docs__"}
    for line, code in blocks():
        try:
            exec(compile(checked_lines(code), f"docs/python.md:{line}", "exec"), namespace)
        except Exception as e:
            pytest.fail(f"docs/python.md, the block at line {line}: {type(e).__name__}: {e}")
