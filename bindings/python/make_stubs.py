#!/usr/bin/env python3
"""Writes the type stubs of the extension, calligraphy/_calligraphy.pyi, with mypy's stubgen.

Run by the build after the module is linked (bindings/python/CMakeLists.txt), with the build's package
on PYTHONPATH:

    PYTHONPATH=build/python python3 bindings/python/make_stubs.py --out build/python

stubgen (mypy 1.0, Debian's python3-mypy) reads a pybind11 module from the signatures at the start of
its docstrings. Where it cannot, this script completes its output from the same signatures:

* keyword-only constructors (`__init__(self: X, *, field: T = ...)`, the parameter classes): stubgen's
  docstring parser does not know the bare `*` and writes `(*args, **kwargs)`;
* static methods (`CharacterLibrary.default()`): written as methods with `self` and no types;
* read-only properties: stubgen takes "<words>: ..." at the start of a property's documentation for its
  type; the type of the getter's signature is used instead;
* `numpy.ndarray[numpy.float64]` (pybind11's spelling) becomes `numpy.typing.NDArray[numpy.float64]`;
* `__hash__ = None` and the import of pandas (which has no type information) get the `type: ignore`
  comments typeshed uses;
* an enum argument takes a member or its spelling (docs/python.md, "Errors"): each parameter typed by an
  enum is `Union[Enum, str]`, and each field holding one an `_EnumField[Enum]`, a descriptor of the stubs
  alone that reads as the member and takes either on assignment (`law.nearest.method = "newton"`).

The result must parse as Python; the script fails otherwise.
"""

import argparse
import ast
import importlib
import inspect
import pathlib
import re
import sys
import tempfile

MODULE = "calligraphy._calligraphy"
PREFIX = MODULE + "."


def split_top_level(text):
    """Splits at commas outside brackets and quotes."""
    parts, depth, quote, current = [], 0, None, ""
    for c in text:
        if quote:
            quote = None if c == quote else quote
        elif c in "'\"":
            quote = c
        elif c in "([{<":  # < > of a default's repr, e.g. <TraceKind.human: 1>
            depth += 1
        elif c in ")]}>":
            depth -= 1
        elif c == "," and depth == 0:
            parts.append(current.strip())
            current = ""
            continue
        current += c
    if current.strip():
        parts.append(current.strip())
    return parts


def parse_signature(doc, name):
    """(arguments, return type) of the pybind11 signature `name(...) -> T` on the docstring's first line."""
    first = (doc or "").splitlines()[0] if doc else ""
    if not first.startswith(name + "("):
        return None
    depth = 0
    for end, c in enumerate(first):
        depth += c == "("
        depth -= c == ")"
        if depth == 0 and c == ")":
            break
    arguments = split_top_level(first[len(name) + 1:end])
    arrow = first[end + 1:].strip()
    returns = arrow[2:].strip() if arrow.startswith("->") else "None"
    return arguments, returns


def stub_argument(argument):
    """'x: T = default' -> 'x: T = ...'; 'self: X' -> 'self'; '*' and '**kw' kept."""
    name, _, rest = argument.partition(":")
    name = name.strip()
    if name == "self" or name.startswith("*"):
        return name.split("=")[0].strip()
    annotation, has_default, _ = rest.partition("=")
    return f"{name}: {annotation.strip()}" + (" = ..." if has_default else "")


def unqualified(text):
    return text.replace(PREFIX, "")


def fix_class(lines, cls):
    """Completes the stub lines of one class (its body, indented by four spaces)."""
    out = []
    i = 0
    while i < len(lines):
        line = lines[i]
        method = re.match(r"    def (\w+)\(self, \*args, \*\*kwargs\) -> (\w+): \.\.\.$", line)
        if method:
            name = method.group(1)
            attribute = inspect.getattr_static(cls, name)
            function = attribute.__func__ if isinstance(attribute, staticmethod) else attribute
            signature = parse_signature(getattr(function, "__doc__", None), name)
            if signature:
                arguments, returns = signature
                prefix = "    @staticmethod\n" if isinstance(attribute, staticmethod) else ""
                rendered = ", ".join(stub_argument(a) for a in arguments)
                out.append(f"{prefix}    def {name}({rendered}) -> {unqualified(returns)}: ...")
                i += 1
                continue
        if line == "    @property" and i + 1 < len(lines):
            prop = re.match(r"    def (\w+)\(self\) -> .*: \.\.\.$", lines[i + 1])
            attribute = inspect.getattr_static(cls, prop.group(1), None) if prop else None
            if isinstance(attribute, property) and attribute.fget is not None:
                signature = parse_signature(attribute.fget.__doc__, "")  # pybind11: "(self: X) -> T"
                if signature:
                    out.append(line)
                    out.append(f"    def {prop.group(1)}(self) -> {unqualified(signature[1])}: ...")
                    i += 2
                    continue
        out.append(line)
        i += 1
    return out


ENUM_FIELD = '''
_E = TypeVar("_E")

class _EnumField(Generic[_E]):  # the stubs' own: an enum field, read as the member, set by member or spelling
    @overload
    def __get__(self, instance: None, owner: Any) -> _EnumField[_E]: ...
    @overload
    def __get__(self, instance: object, owner: Any) -> _E: ...
    def __set__(self, instance: object, value: Union[_E, str]) -> None: ...
'''


def spelled_enums(stub, module):
    """Types every enum parameter as the member or its spelling and every enum field as an `_EnumField`."""
    enums = sorted(name for name, value in vars(module).items()
                   if inspect.isclass(value) and "__members__" in dir(value) and not name.startswith("_"))
    alternation = "|".join(enums)
    enum = re.compile(r"(?<![\w.])((?:" + re.escape(PREFIX) + r")?(?:" + alternation + r"))(?![\w\[])")
    out = []
    for line in stub.splitlines():
        function = re.match(r"(\s*def \w+\()(.*)(\) -> .*)$", line)
        field = re.match(r"(    \w+): (" + alternation + r")$", line)
        if function:
            line = function.group(1) + enum.sub(r"Union[\1, str]", function.group(2)) + function.group(3)
        elif field:
            line = f"{field.group(1)}: _EnumField[{field.group(2)}]"
        out.append(line)
    text = "\n".join(out) + "\n"
    if "_EnumField[" in text:
        first_class = re.search(r"^class ", text, flags=re.MULTILINE).start()
        text = text[:first_class] + ENUM_FIELD.lstrip("\n") + "\n" + text[first_class:]
    return text


def fix(text, module):
    lines = text.splitlines()
    out, i = [], 0
    while i < len(lines):
        header = re.match(r"class (\w+)[(:]", lines[i])
        if not header:
            out.append(lines[i])
            i += 1
            continue
        end = i + 1
        while end < len(lines) and (lines[end].startswith("    ") or lines[end] == ""):
            end += 1
        body = lines[i + 1:end]
        cls = getattr(module, header.group(1), None)
        out.append(lines[i])
        out.extend(fix_class(body, cls) if inspect.isclass(cls) else body)
        i = end
    result = "\n".join(out) + "\n"
    result = re.sub(r"numpy\.ndarray\[(numpy\.\w+)\]", r"numpy.typing.NDArray[\1]", result)
    result = spelled_enums(result, module)
    # Unhashable classes, written as typeshed does.
    result = result.replace("    __hash__: ClassVar[None] = ...\n", "    __hash__: ClassVar[None]  # type: ignore[assignment]\n")
    result = with_imports(result)
    # stubgen leaves out module dunders; the version is the project's (a str).
    result = result.replace("\nTYPICAL_STROKES: tuple\n", "\n__version__: str\nTYPICAL_STROKES: Tuple[TypicalStroke, ...]\n", 1)
    result = with_imports(result)
    # pandas has no type information of its own (pandas-stubs is separate): only the one method's result.
    return result.replace("\nimport pandas\n", "\nimport pandas  # type: ignore[import]\n")


def with_imports(stub):
    """Adds the imports of names the completed signatures use and stubgen did not see."""
    lines = stub.splitlines()
    typing_line = next((k for k, line in enumerate(lines) if line.startswith("from typing import ")), None)
    if typing_line is None:
        lines.insert(0, "from typing import Any")
        typing_line = 0
    imported = set(lines[typing_line][len("from typing import "):].split(", "))
    body = "\n".join(lines[typing_line + 1:])
    for name in ("Any", "ClassVar", "Dict", "Generic", "List", "Mapping", "Optional", "Sequence", "Tuple",
                 "TypeVar", "Union", "overload"):
        if re.search(r"\b" + name + r"\b", body):
            imported.add(name)
    lines[typing_line] = "from typing import " + ", ".join(sorted(imported))
    for module in ("os", "numpy", "numpy.typing", "pandas"):
        if re.search(r"(?<![\w.])" + re.escape(module) + r"\.\w", body) and f"import {module}" not in lines:
            lines.insert(typing_line + 1, f"import {module}")
    return "\n".join(lines) + "\n"


def main(argv):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", required=True, help="the folder holding the calligraphy package")
    args = parser.parse_args(argv)
    # This script's folder holds the package's sources without the extension: import the built package.
    here = pathlib.Path(__file__).resolve().parent
    sys.path[:] = [p for p in sys.path if pathlib.Path(p or ".").resolve() != here]
    from mypy import stubgen

    with tempfile.TemporaryDirectory() as folder:
        stubgen.main(["--quiet", "-m", MODULE, "-o", folder])
        text = (pathlib.Path(folder) / "calligraphy" / "_calligraphy.pyi").read_text(encoding="utf-8")
    stub = fix(text, importlib.import_module(MODULE))
    ast.parse(stub)  # a stub that does not parse is a bug here, not something to install
    target = pathlib.Path(args.out) / "calligraphy" / "_calligraphy.pyi"
    if not target.exists() or target.read_text(encoding="utf-8") != stub:
        target.write_text(stub, encoding="utf-8")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
