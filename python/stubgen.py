# proxima: minimum distance between convex polyhedra.
# SPDX-License-Identifier: BSD-3-Clause
"""Writes the type stubs of the compiled module proxima._proxima.

    PYTHONPATH=build/release/python python3 python/stubgen.py OUT/_proxima.pyi

Debian packages no stub generator for pybind11 (pybind11-stubgen, mypy's
stubgen without its C-module support), so this script reads what pybind11
records: every function's and method's signature lines at the head of its
__doc__ ("name(a: T, b: U = 1.0) -> R", one per overload), property getters'
and setters' signatures, class bases. It writes one stub per public name with
the docstring, and next to OUT an __init__.pyi that re-exports them. The
build runs it after every link of proxima_python (python/CMakeLists.txt), so
the stubs follow the bindings. A signature it cannot read stops it with an
error that names the function: a stub must never silently lie.
"""

import os
import re
import sys
import types

MODULE_PREFIXES = ("proxima._proxima.", "proxima.")
# pybind11's names for py::handle, py::sequence, ... -> typing.
PYBIND11_GENERIC_TYPES = {
    "handle": "typing.Any",
    "sequence": "typing.Sequence[typing.Any]",
    "iterable": "typing.Iterable[typing.Any]",
    "iterator": "typing.Iterator[typing.Any]",
    "function": "typing.Callable[..., typing.Any]",
    "buffer": "typing.Any",
    "args": "typing.Any",
    "kwargs": "typing.Any",
    "tuple": "typing.Tuple[typing.Any, ...]",
    "list": "typing.List[typing.Any]",
    "dict": "typing.Dict[typing.Any, typing.Any]",
}
LITERAL = re.compile(r"^(None|True|False|-?\d+(\.\d*)?([eE][-+]?\d+)?|-?inf|'[^'\\]*'|\"[^\"\\]*\")$")


class StubError(Exception):
    pass


def split_top(text, sep=","):
    """Splits text at sep outside brackets and quotes."""
    parts, depth, quote, start = [], 0, None, 0
    for i, ch in enumerate(text):
        if quote:
            if ch == quote:
                quote = None
        elif ch in "'\"":
            quote = ch
        elif ch in "([{<":
            depth += 1
        elif ch in ")]}>":
            depth -= 1
        elif ch == sep and depth == 0:
            parts.append(text[start:i])
            start = i + 1
    parts.append(text[start:])
    return [p.strip() for p in parts if p.strip()]


def python_type(text):
    """pybind11's rendering of a type -> a type expression valid in a stub."""
    t = text.strip()
    for prefix in MODULE_PREFIXES:
        t = t.replace(prefix, "")
    # numpy.ndarray[numpy.float64] (py::array_t<double>), with or without shape and flags.
    # numpy.ndarray[numpy.float64[3, 1], flags.writeable] (Eigen) too.
    t = re.sub(r"numpy\.ndarray\[numpy\.(\w+)(?:\[[^\]]*\])?[^\]]*\]", r"numpy.typing.NDArray[numpy.\1]", t)
    t = re.sub(r"\bnumpy\.ndarray\b(?!\[)", "numpy.typing.NDArray[typing.Any]", t)
    t = re.sub(r"(?<![\w.])object(?![\w.])", "typing.Any", t)
    t = re.sub(r"(\w)\[\d+\]", r"\1", t)  # std::array<int, 4>: List[int[4]] -> List[int]
    for generic, typed in PYBIND11_GENERIC_TYPES.items():
        t = re.sub(r"(?<![\w.])" + generic + r"(?![\w.\[])", typed, t)
    t = re.sub(r"(?<![\w.])(List|Tuple|Dict|Optional|Union|Callable|Iterator|Iterable|Sequence)\[", r"typing.\1[", t)
    t = re.sub(r"(?<![\w.])os\.PathLike(?!\[)", "os.PathLike[str]", t)
    return t


def parse_signature(line, name, where):
    """'name(a: T, b: U = d) -> R' -> (['a: T', 'b: U = d'], 'R')."""
    m = re.match(r"^" + re.escape(name) + r"\((.*)\)(?:\s*->\s*(.+))?$", line.strip())
    if not m:
        raise StubError(f"{where}: cannot read the signature line {line!r}")
    params = []
    for raw in split_top(m.group(1)):
        if raw in ("*", "/") or raw.startswith("*"):
            params.append(raw if ":" not in raw else raw.split(":")[0] + ": " + python_type(raw.split(":", 1)[1]))
            continue
        head, _, default = raw.partition("=")
        pname, _, ptype = head.partition(":")
        pname, ptype, default = pname.strip(), ptype.strip(), default.strip()
        if not re.match(r"^\w+$", pname):
            raise StubError(f"{where}: cannot read the parameter {raw!r} in {line!r}")
        ptype = python_type(ptype) if ptype else ""
        if default == "None" and ptype and not re.match(r"^(typing\.Any|typing\.Optional\[.*\]|None)$", ptype):
            ptype = f"typing.Optional[{ptype}]"  # pybind11 lets None through for a default of None
        text = pname + (": " + ptype if ptype else "")
        if default:
            text += " = " + (default if LITERAL.match(default) else "...")
        params.append(text)
    return params, python_type(m.group(2) or "None")


def overloads(func, name, where):
    """[(params, return type, doc)] from a pybind11 function's __doc__."""
    doc = func.__doc__ or ""
    lines = doc.split("\n")
    if not lines or not lines[0].startswith(name + "("):
        raise StubError(f"{where}: no pybind11 signature at the head of the docstring: {doc[:80]!r}")
    if len(lines) > 1 and lines[1].strip() == "Overloaded function.":
        chunks = re.split(r"^\d+\. (?=" + re.escape(name) + r"\()", "\n".join(lines[2:]), flags=re.M)
        result = []
        for chunk in chunks:
            if not chunk.strip():
                continue
            sig, _, body = chunk.partition("\n")
            params, ret = parse_signature(sig, name, where)
            result.append((params, ret, body.strip()))
        return result
    params, ret = parse_signature(lines[0], name, where)
    return [(params, ret, "\n".join(lines[1:]).strip())]


def docstring(text, indent):
    if not text:
        return ""
    text = text.replace("\\", "\\\\").replace('"""', '\\"\\"\\"')
    body = "\n".join((indent + l) if l.strip() else "" for l in text.split("\n"))
    return f'{indent}"""\n{body}\n{indent}"""\n'


def emit_function(out, func, name, where, indent, static=False, method=False):
    defs = overloads(func, name, where)
    for params, ret, doc in defs:
        if method and not static:
            if not params or not params[0].startswith("self"):
                raise StubError(f"{where}: a method without self: {params}")
            params = ["self"] + params[1:]
        if len(defs) > 1:
            out.append(f"{indent}@typing.overload\n")
        if static:
            out.append(f"{indent}@staticmethod\n")
        head = f"{indent}def {name}({', '.join(params)}) -> {ret}:"
        if len(defs) > 1:
            # pybind11 takes the first overload that converts, as typing does; the later ones
            # are wider (Any), which type checkers report as an overlap.
            head += "  # type: ignore[misc]"
        if doc:
            out.append(head + "\n" + docstring(doc, indent + "    ") + f"{indent}    ...\n")
        elif len(defs) > 1:
            out.append(head + f"\n{indent}    ...\n")
        else:
            out.append(head + " ...\n")


def property_type(prop, where):
    if prop.fget is None:
        raise StubError(f"{where}: a property without getter")
    sig = (prop.fget.__doc__ or "").split("\n")[0]
    m = re.match(r"^\w*\((.*)\)\s*->\s*(.+)$", sig)
    if not m:
        raise StubError(f"{where}: cannot read the getter's signature {sig!r}")
    return python_type(m.group(2))


def is_pybind_function(obj):
    return isinstance(obj, types.BuiltinFunctionType)


def emit_class(out, cls, name):
    if issubclass(cls, BaseException):
        bases = ", ".join(b.__name__ for b in cls.__bases__)
        out.append(f"class {name}({bases}):\n" + (docstring(cls.__doc__ or "", "    ") or "    ...\n") + "\n")
        return
    # Bases of this module (BodyResult(DistanceResult)); pybind11's own base is left out.
    bases = [b.__name__ for b in cls.__bases__ if b.__module__ in ("proxima", "proxima._proxima")]
    out.append(f"class {name}({', '.join(bases)}):\n" if bases else f"class {name}:\n")
    doc = cls.__doc__ or ""
    out.append(docstring(doc, "    "))
    members = 0
    for attr, value in cls.__dict__.items():
        where = f"{name}.{attr}"
        if attr in ("__doc__", "__module__", "__dict__", "__weakref__", "__new__"):
            continue
        if isinstance(value, staticmethod):
            emit_function(out, value.__func__, attr, where, "    ", static=True, method=True)
        elif isinstance(value, property):
            ptype = property_type(value, where)
            out.append("    @property\n")
            body = docstring(value.__doc__ or "", "        ")
            out.append(f"    def {attr}(self) -> {ptype}:\n" + body + "        ...\n")
            if value.fset is not None:
                out.append(f"    @{attr}.setter\n    def {attr}(self, value: {ptype}) -> None: ...\n")
        elif type(value).__name__ == "instancemethod" or is_pybind_function(value):
            func = getattr(value, "__func__", value)
            if attr.startswith("_") and not (attr.startswith("__") and attr.endswith("__")):
                continue
            emit_function(out, func, attr, where, "    ", method=True)
        elif attr.startswith("_"):
            continue
        else:
            out.append(f"    {attr}: typing.ClassVar[{python_type(type(value).__name__)}]\n")
        members += 1
    if not members and not doc:
        out.append("    ...\n")
    out.append("\n")


def generate(module):
    public = sorted(n for n in dir(module) if not n.startswith("_"))
    out = [
        "# Generated by python/stubgen.py from the compiled module; do not edit.\n",
        docstring(module.__doc__ or "", "").rstrip("\n") + "\n\n",
        "import os\nimport typing\n\nimport numpy\nimport numpy.typing\n\n",
        "__all__ = [\n" + "".join(f'    "{n}",\n' for n in public) + "]\n\n",
    ]
    for name in public:
        value = getattr(module, name)
        if isinstance(value, type):
            emit_class(out, value, name)
        elif is_pybind_function(value):
            emit_function(out, value, name, name, "")
            out.append("\n")
        else:
            out.append(f"{name}: {python_type(type(value).__name__)}\n\n")
    return "".join(out).rstrip("\n") + "\n"


def main(argv):
    if len(argv) != 2:
        sys.stderr.write("usage: stubgen.py OUT/_proxima.pyi\n")
        return 2
    # The module built, found through PYTHONPATH: not the sources next to this script.
    here = os.path.dirname(os.path.abspath(__file__))
    sys.path[:] = [p for p in sys.path if os.path.abspath(p or ".") != here]
    from proxima import _proxima

    try:
        text = generate(_proxima)
        compile(text, "_proxima.pyi", "exec")  # a stub that is not Python stops the build here
    except (StubError, SyntaxError) as e:
        sys.stderr.write(f"stubgen.py: {e}\n")
        return 1
    out_path = argv[1]
    init_path = os.path.join(os.path.dirname(out_path), "__init__.pyi")
    init_text = (
        "# Generated by python/stubgen.py; do not edit.\n"
        "from ._proxima import *\n"
        "from ._proxima import __all__ as __all__\n"
    )
    for path, content in ((out_path, text), (init_path, init_text)):
        old = None
        if os.path.exists(path):
            with open(path, encoding="utf-8") as f:
                old = f.read()
        if old != content:  # unchanged stubs keep their time stamp
            with open(path, "w", encoding="utf-8") as f:
                f.write(content)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
