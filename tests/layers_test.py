#!/usr/bin/env python3
"""The library's layers (docs/layout.md) hold: a module may use only modules
of the layers below its own, so no folder depends on one above it or beside
it, and there is no cycle.  Reads the `use friction_*` statements of src/
and app/.

    tests/layers_test.py SOURCE_ROOT
"""
import os
import re
import sys

# Lowest first; folders on one line are beside each other and may not use
# one another.
LAYERS = [
    ["core"],
    ["ode", "surface"],
    ["law"],
    ["analysis"],
    ["input", "output", "netlist"],
    ["scene"],
    ["afm", "brake", "machine"],
    ["job"],
    ["capi", "."],          # "." is the umbrella module src/friction/friction.f90
    ["app"],
]
RANK = {folder: rank for rank, folders in enumerate(LAYERS) for folder in folders}
# Inside a folder, modules that are layered among themselves (docs/layout.md,
# The AFM scan): lowest first, files on one line beside each other.  A module
# of these may use another of these only from a lower line.
SUBLAYERS = {
    "afm": [
        ["trip", "guard"],
        ["slow_limit"],
        ["deterministic_trip", "langevin_trip", "kramers_trip"],
        ["scan"],
    ],
}


def fortran_files(top):
    for root, _, files in os.walk(top):
        for name in files:
            if name.endswith((".f90", ".F90", ".f90.in", ".inc")):
                yield os.path.join(root, name)


def main():
    root = sys.argv[1]
    sources = list(fortran_files(os.path.join(root, "src", "friction"))) + \
        list(fortran_files(os.path.join(root, "app")))
    folder_of = {}
    for path in sources:
        folder = os.path.relpath(os.path.dirname(path), os.path.join(root, "src", "friction"))
        if folder.startswith(".."):
            folder = "app"
        if folder not in RANK:
            print(f"FAILED: {path}: folder {folder!r} is in no layer (add it to docs/layout.md and this test)")
            sys.exit(1)
        for module in re.findall(r"^\s*module\s+(\w+)\s*$", open(path).read(), re.M | re.I):
            folder_of[module.lower()] = folder
    problems = []
    for path in sources:
        folder = os.path.relpath(os.path.dirname(path), os.path.join(root, "src", "friction"))
        folder = "app" if folder.startswith("..") else folder
        for line, used in re.findall(r"^(\s*use\s+(friction\w*))", open(path).read(), re.M | re.I):
            target = folder_of.get(used.lower())
            if target is None or target == folder:
                continue
            if RANK[target] >= RANK[folder]:
                problems.append(f"{os.path.relpath(path, root)}: {folder}/ uses {used} of {target}/")
    for folder, rows in SUBLAYERS.items():
        sub_rank = {f"friction_{folder}_{base}": rank for rank, bases in enumerate(rows) for base in bases}
        for path in sources:
            here = os.path.relpath(os.path.dirname(path), os.path.join(root, "src", "friction"))
            base = os.path.basename(path).split(".")[0]
            module = f"friction_{folder}_{base}"
            if here != folder or module not in sub_rank:
                continue
            for _, used in re.findall(r"^(\s*use\s+(friction\w*))", open(path).read(), re.M | re.I):
                target = sub_rank.get(used.lower())
                if target is not None and used.lower() != module and target >= sub_rank[module]:
                    problems.append(f"{os.path.relpath(path, root)}: {module} uses {used}, on its own line "
                                    f"or above it in {folder}/")
        for base in (base for bases in rows for base in bases):
            if not os.path.exists(os.path.join(root, "src", "friction", folder, base + ".f90")):
                problems.append(f"src/friction/{folder}/{base}.f90: layered in this test but missing")
    # Each file is named after its module or submodule (docs/layout.md, folders are
    # namespaces): friction_<folder>_<file>, friction_<file> in core/,
    # friction_<folder> for the file named as its folder.
    for path in sources:
        folder = os.path.relpath(os.path.dirname(path), os.path.join(root, "src", "friction"))
        folder = "app" if folder.startswith("..") else folder
        base = os.path.basename(path).split(".")[0]
        expected = {"friction_" + base if folder in ("core", ".") else f"friction_{folder}_{base}",
                    f"friction_{folder}"}
        if folder == "." and base == "friction":
            expected = {"friction"}
        text = open(path).read()
        modules = re.findall(r"^\s*module\s+(\w+)\s*$", text, re.M | re.I) + \
            re.findall(r"^\s*submodule\s*\(\s*\w+\s*\)\s*(\w+)\s*$", text, re.M | re.I)
        for module in modules:
            if module.lower() not in expected and not (folder == "core" and base == module.lower()[9:]):
                problems.append(f"{os.path.relpath(path, root)}: module {module}, not named after its file "
                                f"({' or '.join(sorted(expected))})")
    if problems:
        print("FAILED: layer violations:\n  " + "\n  ".join(problems))
        sys.exit(1)
    print(f"{len(sources)} files, {len(folder_of)} modules: every use goes down the layers")


if __name__ == "__main__":
    main()
