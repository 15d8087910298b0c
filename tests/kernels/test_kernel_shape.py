"""The kernels keep a readable shape: no function in kernels/*.py is longer than MAX_LINES
lines or takes more than MAX_PARAMS parameters.

The unloading loop passes grouped values (the named tuples of ``kernels.solve``: MeshArrays,
Physics, StepControl, RunState, Records, Work) and runs its time step as named parts, so
that no kernel grows back into one function with dozens of positional arrays.
"""
import ast
import pathlib

import pytest

import sweep.kernels

#: longest function allowed: lines from ``def`` to its last line, docstring and comments
#: included (newton, the longest, has 78)
MAX_LINES = 80
#: most parameters allowed (``*args`` and ``**kwargs`` count one each)
MAX_PARAMS = 12

KERNELS = pathlib.Path(sweep.kernels.__file__).parent
SOURCES = sorted(KERNELS.glob("*.py"))


def shapes(source):
    """(name, lines, parameters) of every function in ``source``, nested ones included."""
    out = []
    for node in ast.walk(ast.parse(source)):
        if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
            a = node.args
            n = (len(a.posonlyargs) + len(a.args) + len(a.kwonlyargs)
                 + (a.vararg is not None) + (a.kwarg is not None))
            out.append((node.name, node.end_lineno - node.lineno + 1, n))
    return out


def test_shape_counts_lines_and_parameters():
    src = ("@deco\n"
           "def f(a, b, /, c, *d, e=1, **f):\n"
           "    x = 1\n"
           "\n"
           "    return x\n"
           "\n"
           "async def g():\n"
           "    def h(): pass\n")
    assert sorted(shapes(src)) == [("f", 4, 6), ("g", 2, 0), ("h", 1, 0)]


def test_the_kernel_sources_are_found():
    names = {p.name for p in SOURCES}
    assert {"solve.py", "jacobian.py", "history.py", "interface.py"} <= names


@pytest.mark.parametrize("path", SOURCES, ids=lambda p: p.name)
def test_kernel_functions_are_short_with_few_parameters(path):
    found = shapes(path.read_text())
    assert found or path.name == "__init__.py"
    too_long = [(name, lines) for name, lines, _ in found if lines > MAX_LINES]
    too_many = [(name, n) for name, _, n in found if n > MAX_PARAMS]
    assert not too_long, f"{path.name}: functions longer than {MAX_LINES} lines: {too_long}"
    assert not too_many, f"{path.name}: more than {MAX_PARAMS} parameters: {too_many}"
