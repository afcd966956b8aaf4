"""A cached kernel is recompiled when a module it imports changes (pegame.kernel_stamps),
and loaded from the cache when only a module it does not reach changed."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

from pegame import kernel_stamps

#: a package of pegame's distributions: ``outer`` (in b) calls and inlines ``inner`` (in a)
FILES = {
    "__init__.py": "",
    "a.py": (
        "from numba import njit\n\n\n"
        "@njit(cache=True, inline='always')\ndef inner(x):\n    return x + 1\n"
    ),
    "b.py": (
        "import pegame  # noqa: F401  (pegame's cache locator, as any plugin imports it)\n"
        "from numba import njit\n\nfrom pegame_stamps_probe.a import inner\n\n\n"
        "@njit(cache=True)\ndef outer(x):\n    return inner(x) * 10\n"
    ),
    "c.py": "VALUE = 1\n",
}

RUN = """
import json
from pegame_stamps_probe.b import outer
value = outer(1)
print(json.dumps([value, sum(outer.stats.cache_hits.values())]))
"""


def run(root: Path) -> tuple[int, int]:
    """(outer(1), cache hits) in a fresh process with its own numba cache."""
    env = {
        **os.environ,
        "NUMBA_CACHE_DIR": str(root / "cache"),
        "PYTHONPATH": os.pathsep.join([str(root), os.environ.get("PYTHONPATH", "")]),
    }
    done = subprocess.run(
        [sys.executable, "-c", RUN], env=env, capture_output=True, text=True, timeout=300
    )
    assert done.returncode == 0, done.stderr
    value, hits = json.loads(done.stdout.strip().splitlines()[-1])
    return value, hits


@pytest.mark.slow
def test_an_edited_callee_in_another_module_is_compiled_anew_not_loaded_stale(tmp_path):
    package = tmp_path / "pegame_stamps_probe"
    package.mkdir()
    for name, text in FILES.items():
        (package / name).write_text(text)
    assert run(tmp_path) == (20, 0)  # compiled
    assert run(tmp_path) == (20, 1)  # loaded from the cache
    (package / "c.py").write_text("VALUE = 2\n")  # a module outer does not import
    assert run(tmp_path) == (20, 1)
    (package / "a.py").write_text(FILES["a.py"].replace("x + 1", "x + 2"))
    # numba's own stamp covers b.py only: it loaded outer with the old inner, 20
    assert run(tmp_path) == (30, 0)


def test_the_stamp_follows_imports_relative_or_absolute_and_skips_other_packages(tmp_path):
    package = tmp_path / "pegame_closure_probe"
    (package / "sub").mkdir(parents=True)
    (package / "__init__.py").write_text("")
    (package / "sub" / "__init__.py").write_text("")
    (package / "sub" / "x.py").write_text("from .. import y\nimport numpy\n")
    (package / "y.py").write_text("from pegame_closure_probe.sub import (\n    z,  # z\n)\n")
    (package / "sub" / "z.py").write_text("Z = 1\n")
    (package / "w.py").write_text("W = 1\n")
    sys.path.insert(0, str(tmp_path))
    try:
        path = package / "sub" / "x.py"
        found = kernel_stamps._imports(path, "pegame_closure_probe.sub.x")
        assert "pegame_closure_probe.y" in found and "numpy" not in found
        before = kernel_stamps.closure_stamp("pegame_closure_probe.sub.x")
        kernel_stamps.closure_stamp.cache_clear()
        kernel_stamps._content_hash.cache_clear()
        (package / "w.py").write_text("W = 2\n")  # not reached
        assert kernel_stamps.closure_stamp("pegame_closure_probe.sub.x") == before
        kernel_stamps.closure_stamp.cache_clear()
        kernel_stamps._content_hash.cache_clear()
        (package / "sub" / "z.py").write_text("Z = 2\n")  # reached through y
        assert kernel_stamps.closure_stamp("pegame_closure_probe.sub.x") != before
    finally:
        sys.path.remove(str(tmp_path))
        kernel_stamps.closure_stamp.cache_clear()
        kernel_stamps._content_hash.cache_clear()
