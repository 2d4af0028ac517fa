"""The compiled kernels stay quick to compile (issue 28: a fresh clone's `make test` and a
user's first `make reproduce` compile every kernel once).

numba compiles an array-to-array slice assignment (``u[:, :] = up[t]``) or ``np.sort`` of a
slice with its broadcasting checks and their error messages: about 4 s and 2 s of compilation
per process on a cold cache (measured 2026-11-27; a copy element by element compiles in a
tenth of a second, and gives the same numbers). A kernel is a function whose ``def`` line
says ``pragma: no cover`` in a module that :mod:`sim.lsq.compile` compiles; scalar fills
(``F[:, :] = 0.0``) are cheap and allowed.
"""

import ast
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
#: the files that hold the source of compiled kernels (and their helpers)
SOURCES = [
    "sim/lsq/group_kernel.py",
    "sim/lsq/group_kernel_solve.py",
    "sim/lsq/linear_kernel.py",
    "sim/lsq/normals.py",
    "sim/lsq/selinv.py",
    "sim/lsq/sparse_batch.py",
    "sim/instruments/ranges/multilateration_kernel.py",
    "sim/instruments/plotter/polynomial_kernel.py",
    "sim/instruments/plotter/errorfield_kernel.py",
    "sim/studies/network/kernel.py",
]


def kernels(text: str) -> list[ast.FunctionDef]:
    """The functions of ``text`` whose ``def`` line (or the line closing its arguments) says
    ``pragma: no cover``: the compiled kernels and helpers of the suite's convention."""
    lines = text.splitlines()
    out = []
    for node in ast.walk(ast.parse(text)):
        if isinstance(node, ast.FunctionDef):
            head = lines[node.lineno - 1 : node.body[0].lineno - 1]
            if any("pragma: no cover" in ln for ln in head):
                out.append(node)
    return out


def _scalar(node: ast.AST) -> bool:
    if isinstance(node, ast.UnaryOp):
        node = node.operand
    return isinstance(node, ast.Constant)


def slow_constructs(fn: ast.FunctionDef) -> list[str]:
    """``line: what`` for each array-to-array slice assignment and ``np.sort`` call in ``fn``."""
    found = []
    for node in ast.walk(fn):
        if isinstance(node, (ast.Assign, ast.AugAssign)):
            targets = node.targets if isinstance(node, ast.Assign) else [node.target]
            for t in targets:
                if isinstance(t, ast.Subscript) and not _scalar(node.value):
                    idx = t.slice.elts if isinstance(t.slice, ast.Tuple) else [t.slice]
                    if any(isinstance(i, ast.Slice) for i in idx):
                        found.append(f"{node.lineno}: an array copied into a slice")
        if (
            isinstance(node, ast.Call)
            and isinstance(node.func, ast.Attribute)
            and node.func.attr == "sort"
            and isinstance(node.func.value, ast.Name)
            and node.func.value.id == "np"
        ):
            found.append(f"{node.lineno}: np.sort (sort the slice in place)")
    return found


def test_the_checker_finds_a_slice_copy_and_allows_a_scalar_fill():
    src = (
        "def k(u, up, Li):  # pragma: no cover\n"
        "    u[:, :] = 0.0\n"
        "    u[0, :] = -1.0\n"
        "    u[:, :] = up[0]\n"
        "    Li[1:3] = np.sort(Li[1:3])\n"
        "    Li[1:3].sort()\n"
        "def py(u, up):\n"
        "    u[:, :] = up[0]\n"
    )
    (fn,) = kernels(src)
    assert slow_constructs(fn) == [
        "4: an array copied into a slice",
        "5: an array copied into a slice",
        "5: np.sort (sort the slice in place)",
    ]


@pytest.mark.parametrize("path", SOURCES)
def test_no_kernel_copies_an_array_into_a_slice(path):
    text = (ROOT / path).read_text(encoding="utf-8")
    found = kernels(text)
    assert found, f"{path}: no kernel found (is the pragma convention still in use?)"
    bad = {fn.name: slow_constructs(fn) for fn in found}
    assert not any(bad.values()), {k: v for k, v in bad.items() if v}
