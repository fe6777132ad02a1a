"""The public Python API has type hints and numpydoc docstrings (docs/python.md#layout-and-tests).

Public: what `friction.__all__` and the `__all__` of friction.plot, fit, law
and thermal name, and the public methods and properties of their classes
(inherited ones too, where a module of the package defines them).  Every
parameter but self and the return carry annotations; numpydoc's own
validation (numpydoc.validate) finds no missing docstring (GL08), no
undocumented or unknown parameter (PR01, PR02) and no missing Returns
section where the code returns a value (RT01); a class documents its
constructor's parameters.
"""
import dataclasses
import importlib
import inspect

import pytest
from numpydoc.validate import validate

CHECKS = {"GL08": "no docstring", "PR01": "parameters not documented", "PR02": "unknown parameters documented",
          "RT01": "no Returns section"}
MODULES = ("friction", "friction.plot", "friction.fit", "friction.law", "friction.thermal")


def _ours(obj):
    return getattr(obj, "__module__", "").split(".")[0] == "friction"


def public_api():
    """(qualified name, object) of every public function, class, method and property."""
    seen, found = set(), []
    for module_name in MODULES:
        module = importlib.import_module(module_name)
        for name in module.__all__:
            obj = getattr(module, name)
            if not (inspect.isfunction(obj) or inspect.isclass(obj)) or not _ours(obj) or id(obj) in seen:
                continue
            seen.add(id(obj))
            qualified = f"{obj.__module__}.{obj.__qualname__}"
            found.append((qualified, obj))
            if not inspect.isclass(obj):
                continue
            taken = set()   # a method a subclass overrides is the subclass's
            for klass in obj.__mro__:
                if not _ours(klass):
                    continue
                for attr, member in vars(klass).items():
                    if attr.startswith("_") or id(member) in seen or attr in taken:
                        continue
                    taken.add(attr)
                    function = member.fget if isinstance(member, property) else member
                    # (matplotlib gives a Figure subclass its own `set`: not ours)
                    if (inspect.isfunction(function) and _ours(function)
                            and f"{klass.__qualname__}.{attr}" in function.__qualname__):
                        seen.add(id(member))
                        found.append((f"{klass.__module__}.{klass.__qualname__}.{attr}", member))
    return found


API = public_api()


def test_the_walk_finds_the_api():
    names = {name.split(".")[-1] for name, _ in API}
    assert {"run", "load", "Config", "afm_maps", "image", "Law", "fit_sang", "set", "afm_line"} <= names
    assert len(API) > 80


def _hint_problems(func):
    signature = inspect.signature(func)
    missing = [p.name for p in signature.parameters.values()
               if p.name not in ("self", "cls") and p.annotation is inspect.Parameter.empty]
    problems = [f"parameters without a type hint: {missing}"] if missing else []
    if signature.return_annotation is inspect.Signature.empty:
        problems.append("no return type hint")
    return problems


@pytest.mark.parametrize("name, obj", API, ids=[name for name, _ in API])
def test_hints_and_numpydoc(name, obj):
    problems = []
    codes = set(CHECKS)
    if inspect.isclass(obj):
        init = obj.__dict__.get("__init__")
        if init is not None and not dataclasses.is_dataclass(obj) and _ours(init):
            problems += _hint_problems(init)
        if not (dataclasses.is_dataclass(obj) or hasattr(obj, "_fields")) and not _ours(obj.__init__):
            codes.discard("PR01")   # a constructor inherited (plot.Figure: matplotlib's) is documented there
    else:
        problems += _hint_problems(obj.fget if isinstance(obj, property) else obj)
    errors = {code for code, _ in validate(name)["errors"]}
    problems += [f"numpydoc {code}: {CHECKS[code]}" for code in sorted(errors & codes)]
    assert not problems, f"{name}: " + "; ".join(problems)


def test_the_check_fails_without_hints_or_docstring():
    """The check itself: hints missing are found, and a public function
    whose docstring is gone fails numpydoc's validation."""
    def bare(data, line=None):
        return data

    assert _hint_problems(bare) == ["parameters without a type hint: ['data', 'line']", "no return type hint"]
    import friction.plot
    saved = friction.plot.afm_maps.__doc__
    friction.plot.afm_maps.__doc__ = None
    try:
        errors = {code for code, _ in validate("friction.plot.afm_maps")["errors"]}
    finally:
        friction.plot.afm_maps.__doc__ = saved
    assert "GL08" in errors
    friction.plot.afm_maps.__doc__ = saved.split("Parameters")[0]   # the sections gone
    try:
        errors = {code for code, _ in validate("friction.plot.afm_maps")["errors"]}
    finally:
        friction.plot.afm_maps.__doc__ = saved
    assert {"PR01", "RT01"} <= errors
