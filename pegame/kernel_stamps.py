"""A cached numba kernel of pegame is stale when any module it imports has changed, not
only its own.

Numba caches a ``@njit(cache=True)`` kernel on disk with a stamp of its own module's
source (a content hash, ``numba.core.caching``) and loads the cached machine code while
that stamp holds. But the machine code also holds every kernel it calls or inlines from
other modules: edit ``pegame/numerics.py`` and a kernel of ``pegame/vector/kernels.py``
that calls its ``hypot`` keeps the old ``hypot``, with no error, until its own module
changes.

:func:`install` puts :class:`ImportClosureLocator` first among numba's cache locators.
For a function of a pegame distribution's module (``pegame``, ``pegame_pybullet``, ...)
it keeps the locator numba would choose (the same cache directory: beside the module,
under ``NUMBA_CACHE_DIR``, or the user-wide one of a read-only install) and stamps the
kernel with the content of its module and of every module of pegame's distributions that
it imports, directly or through others (read from their import statements, so nothing is
imported). An edit of any of them recompiles the kernel; an edit of a module it does not
reach (the report, the docs) does not. Other packages' kernels
keep numba's own locators. Nothing is deleted: a stale index entry is overwritten when
the kernel is saved again.
"""

from __future__ import annotations

import hashlib
import importlib.util
import re
import sys
from functools import cache
from pathlib import Path
from typing import Any

from numba.core import caching

#: the top-level packages whose kernels get the import-closure stamp
PREFIX = "pegame"
#: numba's list of cache locator classes, tried in order (of ``CacheImpl`` in recent
#: numba, ``_CacheImpl`` in older)
_IMPL: Any = getattr(caching, "CacheImpl", None) or caching.__dict__["_CacheImpl"]
_LOCATORS: list = _IMPL._locator_classes


def _covered(module: str) -> bool:
    return module.split(".")[0].startswith(PREFIX)


@cache
def _package_root(top: str) -> Path | None:
    """The directory of the top-level package ``top`` (found without importing it)."""
    loaded = sys.modules.get(top)
    locations = getattr(loaded, "__path__", None)
    if locations is None:
        try:
            spec = importlib.util.find_spec(top)
        except (ImportError, ValueError):
            return None
        locations = spec.submodule_search_locations if spec is not None else None
    return Path(next(iter(locations))) if locations else None


@cache
def _module_file(name: str) -> Path | None:
    """The source file of module ``name`` of a covered package, None when there is none
    (a name that is not a module, e.g. a function imported from one)."""
    if not _covered(name):
        return None
    top, _, rest = name.partition(".")
    root = _package_root(top)
    if root is None:
        return None
    base = root.joinpath(*rest.split(".")) if rest else root
    for path in ([base.with_name(base.name + ".py")] if rest else []) + [base / "__init__.py"]:
        if path.is_file():
            return path
    return None


#: an import statement: ``from X import names`` (names parenthesised over lines or not)
#: or ``import names``
_IMPORT = re.compile(
    r"^[ \t]*(?:from[ \t]+(\.*[\w.]*)[ \t]+import[ \t]+(\([^)]*\)|[^\n]*)|import[ \t]+([^\n]*))",
    re.MULTILINE,
)


def _names(text: str) -> list[str]:
    """The names of an import statement's list (``a as b, c``, comments dropped)."""
    lines = [line.split("#")[0] for line in text.strip("()").splitlines()]
    names = " ".join(lines).split(",")
    return [name.split()[0] for name in names if name.split()]


@cache
def _imports(path: Path, module: str) -> tuple[str, ...]:
    """The covered modules that ``path`` (module ``module``) imports by name: ``import a.b``
    and ``from a import b`` (``a.b`` when it is a module, else ``a``), relative or not. The
    statements are found by a pattern, not parsed (a tenth of the time): a docstring line
    that reads as an import only adds a module to the stamp."""
    package = module if path.name == "__init__.py" else module.rpartition(".")[0]
    found: list[str] = []
    for match in _IMPORT.finditer(path.read_text(encoding="utf-8")):
        base, listed, plain = match.groups()
        if plain is not None:
            found += _names(plain)
            continue
        level = len(base) - len(base.lstrip("."))
        base = base.lstrip(".")
        if level:
            parts = package.split(".")[: len(package.split(".")) - level + 1]
            base = ".".join([*parts, base] if base else parts)
        found.append(base)
        found += [f"{base}.{name}" for name in _names(listed)]
    return tuple(sorted({name for name in found if _covered(name)}))


@cache
def _content_hash(path: Path) -> bytes:
    return hashlib.sha256(path.read_bytes()).digest()


@cache
def closure_stamp(module: str) -> str:
    """A hash of the source of ``module`` and of every covered module it imports,
    directly or through others (their packages' ``__init__`` included)."""
    seen: dict[str, Path] = {}
    todo = [module]
    while todo:
        name = todo.pop()
        if name in seen:
            continue
        path = _module_file(name)
        if path is None:
            continue
        seen[name] = path
        parents = [name.rsplit(".", k)[0] for k in range(1, name.count(".") + 1)]
        todo += [*_imports(path, name), *parents]
    digest = hashlib.sha256()
    for name in sorted(seen):
        digest.update(name.encode())
        digest.update(_content_hash(seen[name]))
    return digest.hexdigest()


class ImportClosureLocator(caching._CacheLocator):
    """Numba's own locator for a covered function, with :func:`closure_stamp` added to
    its source stamp."""

    def __init__(self, inner: caching._CacheLocator, module: str) -> None:
        self._inner, self._module = inner, module

    def ensure_cache_path(self) -> None:
        self._inner.ensure_cache_path()

    def get_cache_path(self) -> str:
        return str(self._inner.get_cache_path())

    def get_source_stamp(self) -> Any:
        return (self._inner.get_source_stamp(), closure_stamp(self._module))

    def get_disambiguator(self) -> str:
        return str(self._inner.get_disambiguator())

    @classmethod
    def from_function(cls, py_func: Any, py_file: str) -> ImportClosureLocator | None:
        module = getattr(py_func, "__module__", "") or ""
        if not _covered(module):
            return None
        for other in _LOCATORS:
            if other is cls:
                continue
            inner = other.from_function(py_func, py_file)
            if inner is not None:
                return cls(inner, module)
        return None


def install() -> None:
    """Put :class:`ImportClosureLocator` first among numba's cache locators (once). Call
    it before any covered kernel is defined: numba picks a kernel's locator when it is
    decorated."""
    if ImportClosureLocator not in _LOCATORS:
        _LOCATORS.insert(0, ImportClosureLocator)
