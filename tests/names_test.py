#!/usr/bin/env python3
"""Names become kinds where the configuration is checked: no scene, model or
potential name is compared, and no scene's type is selected, outside the
scene factory and the configurations (docs/layout.md).

How it finds them.  The names are read from the source, not listed here:
the scene names from `scene_names` in src/friction/job/factory.f90, and the
model and potential names from every `*model_names` or `potential_names`
parameter array of the configuration modules (the files that declare them,
and their submodules).
A named text constant whose value is one of those names (`model_switched =
'switched'`) counts as the name.  In every other Fortran file of src/ and
app/, with comments removed, it fails on
  - a comparison `== 'name'`, `/= 'name'`, `'name' ==`, `'name' /=`, or the
    same with such a constant;
  - a `case ('name'` or `case (constant`;
  - `type is (X)` where X is a type extending `scene`.

    tests/names_test.py SOURCE_ROOT
"""
import os
import re
import sys

NAME_LISTS = re.compile(
    r"character\(len=\*\),\s*parameter\s*::\s*(\w*(?:model_names|potential_names|scene_names))\s*\(\d+\)\s*=\s*"
    r"\[character\(len=\d+\)\s*::([^\]]*)\]", re.I)
CONSTANT = re.compile(r"character\(len=\*\),\s*parameter\s*::\s*(.*)$", re.I | re.M)


def fortran_files(top):
    for root, _, files in os.walk(top):
        for name in sorted(files):
            if name.endswith((".f90", ".F90", ".f90.in")):
                yield os.path.join(root, name)


def code_of(text):
    """The text with `!` comments removed (outside quotes) and continuation lines joined."""
    out = []
    for line in text.splitlines():
        quote = None
        for i, ch in enumerate(line):
            if quote:
                if ch == quote:
                    quote = None
            elif ch in "'\"":
                quote = ch
            elif ch == "!":
                line = line[:i]
                break
        out.append(line)
    return re.sub(r"&\s*\n\s*&?", " ", "\n".join(out))


def main():
    root = sys.argv[1]
    sources = list(fortran_files(os.path.join(root, "src", "friction"))) + \
        list(fortran_files(os.path.join(root, "app")))
    names, owners = set(), set()
    for path in sources:
        text = code_of(open(path, encoding="utf-8").read())
        for _, values in NAME_LISTS.findall(text):
            found = re.findall(r"'([^']+)'", values)
            if found:
                names.update(found)
                owners.add(path)
    # A configuration's submodule (its checks) is part of the configuration.
    owner_modules = {m.lower() for path in owners
                     for m in re.findall(r"^\s*module\s+(\w+)\s*$", open(path, encoding="utf-8").read(), re.M | re.I)}
    for path in sources:
        parent = re.search(r"^\s*submodule\s*\(\s*(\w+)", open(path, encoding="utf-8").read(), re.M | re.I)
        if parent and parent.group(1).lower() in owner_modules:
            owners.add(path)
    factory = os.path.join(root, "src", "friction", "job", "factory.f90")
    if "afm" not in names or "switched" not in names or "lj" not in names or factory not in owners:
        print(f"FAILED: the name lists were not found (names {sorted(names)}): has their declaration changed?")
        return 1
    constants = set()
    scene_types = set()
    for path in sources:
        text = code_of(open(path, encoding="utf-8").read())
        for declaration in CONSTANT.findall(text):
            for name, value in re.findall(r"(\w+)\s*=\s*'([^']*)'", declaration):
                if value in names:
                    constants.add(name.lower())
        scene_types.update(t.lower() for t in re.findall(r"type\s*,\s*extends\(\s*scene\s*\)\s*::\s*(\w+)", text,
                                                         re.I))
    quoted = "|".join(re.escape(n) for n in sorted(names))
    named = "|".join(sorted(constants)) or "(?!)"
    literal = rf"'(?:{quoted})'"
    patterns = [
        re.compile(rf"(?:==|/=)\s*(?:trim\()?\s*(?:{literal}|\b(?:{named})\b)", re.I),
        re.compile(rf"(?:{literal}|\b(?:{named})\b)\s*\)?\s*(?:==|/=)", re.I),
        re.compile(rf"\bcase\s*\(\s*(?:{literal}|\b(?:{named})\b)", re.I),
    ]
    if scene_types:
        patterns.append(re.compile(rf"\btype\s+is\s*\(\s*(?:{'|'.join(sorted(scene_types))})\s*\)", re.I))
    problems = []
    for path in sources:
        if path in owners:
            continue
        text = code_of(open(path, encoding="utf-8").read())
        for number, line in enumerate(text.splitlines(), 1):
            for pattern in patterns:
                match = pattern.search(line)
                if match:
                    problems.append(f"{os.path.relpath(path, root)}: {match.group(0).strip()!r}")
    if problems:
        print("FAILED: a scene, model or potential name decided outside the factory and the configurations "
              "(turn it into a kind where the configuration is checked):")
        print("\n".join("  " + p for p in problems))
        return 1
    print(f"ok: {len(names)} names ({', '.join(sorted(names))}), {len(constants)} constants and "
          f"{len(scene_types)} scene types; decided in {len(owners)} files only")
    return 0


if __name__ == "__main__":
    sys.exit(main())
