#!/usr/bin/env python3
"""The commands of the documentation run as written (CTest: doc-commands).

Reads README.md and docs/*.md and runs every fenced ```sh block, command by
command, in a scratch directory set up like a fresh clone: a copy of the
files git tracks (`git ls-files`; never the user's own outputs such as a
hopg.h5 left by scripts/run-example) and the build directory linked as
build/ (a script that finds the repository from its own resolved path finds
the scratch directory and its build/).  The blocks of
a page run in order in the page's own scratch directory; each block runs in a
fresh bash, its commands one after another as typed into one shell.  A
command that exits non-zero fails the test with the page and line.

An HTML comment on the last non-blank line before a block changes that:

    <!-- not run: REASON -->    the block is skipped (say why)
    <!-- exit N -->             the block's last command must exit with N,
                                every other command with 0
    <!-- run: python3 -->       a ```python block: run it with python3

Other blocks (```python without the marker, ```c, ```cmake, plain ```) are
not run.  The test also checks every relative link of the pages (the file
exists inside the repository, an #anchor names a heading of its page) and
that the runs leave the source tree as they found it.

    doc_commands.py --source DIR --build DIR [--work DIR] [--keep]
                    [--timeout S] [--list] [PAGE.md ...]

Exit code 0 when every command behaved, 1 otherwise.
"""

from __future__ import annotations

import argparse
import os
import re
import shlex
import shutil
import subprocess
import sys
import tempfile
import time
from dataclasses import dataclass, field
from pathlib import Path

# Open MPI as root and with more ranks than cores: settings of this test, not
# of the documented commands (which must not need them on a user's machine).
TEST_ENV = {
    "OMPI_ALLOW_RUN_AS_ROOT": "1",
    "OMPI_ALLOW_RUN_AS_ROOT_CONFIRM": "1",
    "OMPI_MCA_rmaps_base_oversubscribe": "1",
    # Python run from the scratch copy of scripts/ writes no caches anywhere.
    "PYTHONDONTWRITEBYTECODE": "1",
    "MPLBACKEND": "Agg",
}

FENCE = re.compile(r"^(\s*)(`{3,})\s*([\w+-]*)")
MARKER = re.compile(r"^<!--\s*(.*?)\s*-->$")
LINK = re.compile(r"!?\[(?:[^\]\\]|\\.)*\]\(([^)\s]+)(?:\s+\"[^\"]*\")?\)")
HEADING = re.compile(r"^(#{1,6})\s+(.*?)\s*#*\s*$")


@dataclass
class Command:
    line: int            # 1-based line of the command's first line in the page
    text: str


@dataclass
class Block:
    page: Path
    line: int            # line of the opening fence
    lang: str
    body: list[str]
    body_line: int       # line of the first body line
    marker: str | None = None
    commands: list[Command] = field(default_factory=list)

    name: str = ""       # the page as the messages name it (docs/cli.md)

    def where(self, line: int | None = None) -> str:
        return f"{self.name or self.page.name}:{line or self.line}"


def parse_page(page: Path) -> tuple[list[Block], list[tuple[int, str]], list[str]]:
    """Fenced blocks, the links outside them (line, target), and the headings."""
    blocks: list[Block] = []
    links: list[tuple[int, str]] = []
    headings: list[str] = []
    lines = page.read_text(encoding="utf-8").split("\n")
    i = 0
    last_nonblank = ""
    while i < len(lines):
        m = FENCE.match(lines[i])
        if m:
            ticks = m.group(2)
            start = i
            body = []
            i += 1
            while i < len(lines) and not lines[i].strip().startswith(ticks):
                body.append(lines[i])
                i += 1
            marker = None
            mm = MARKER.match(last_nonblank.strip())
            if mm:
                marker = mm.group(1)
            blocks.append(Block(page, start + 1, m.group(3).lower(), body, start + 2, marker))
            last_nonblank = ""
            i += 1
            continue
        text = lines[i]
        h = HEADING.match(text)
        if h:
            headings.append(h.group(2))
        # Links outside code spans.
        for found in LINK.finditer(re.sub(r"`[^`]*`", "", text)):
            links.append((i + 1, found.group(1)))
        if text.strip():
            last_nonblank = text
        i += 1
    return blocks, links, headings


def split_commands(block: Block) -> list[Command]:
    """Command lines of a sh block: comments and blank lines dropped,
    backslash continuations joined."""
    commands = []
    pending: list[str] = []
    first = 0
    for offset, raw in enumerate(block.body):
        line = raw.rstrip()
        if not pending:
            if not line.strip() or line.lstrip().startswith("#"):
                continue
            first = block.body_line + offset
        if line.endswith("\\"):
            pending.append(line[:-1])
            continue
        pending.append(line)
        commands.append(Command(first, "\n".join(pending)))
        pending = []
    if pending:
        commands.append(Command(first, "\n".join(pending)))
    return commands


def slug(heading: str) -> str:
    """The anchor a Markdown renderer (GitHub's rule) gives a heading."""
    text = re.sub(r"\[([^\]]*)\]\([^)]*\)", r"\1", heading)   # links keep their text
    text = text.replace("`", "").replace("*", "").strip().lower()
    text = re.sub(r"[^\w\- ]", "", text)
    return text.replace(" ", "-")


def anchors(headings: list[str]) -> set[str]:
    seen: dict[str, int] = {}
    result = set()
    for h in headings:
        s = slug(h)
        if s in seen:
            seen[s] += 1
            result.add(f"{s}-{seen[s]}")
        else:
            seen[s] = 0
            result.add(s)
    return result


def check_links(source: Path, pages: list[Path]) -> list[str]:
    problems = []
    parsed = {p.resolve(): parse_page(p) for p in pages}
    for page in pages:
        _, links, headings = parsed[page.resolve()]
        for line, target in links:
            where = f"{page.relative_to(source)}:{line}"
            if re.match(r"^[a-z][a-z0-9+.-]*:", target):   # http:, mailto:, ...
                continue
            path_part, _, anchor = target.partition("#")
            dest = (page.parent / path_part).resolve() if path_part else page.resolve()
            try:
                dest.relative_to(source.resolve())
            except ValueError:
                problems.append(f"{where}: link {target} points outside the repository")
                continue
            if not dest.exists():
                problems.append(f"{where}: link {target}: no such file")
                continue
            if anchor:
                if dest.suffix != ".md":
                    problems.append(f"{where}: link {target}: an anchor into a non-Markdown file")
                    continue
                if dest not in parsed:
                    parsed[dest] = parse_page(dest)
                if anchor not in anchors(parsed[dest][2]):
                    problems.append(f"{where}: link {target}: no heading with anchor #{anchor} "
                                    f"in {dest.relative_to(source.resolve())}")
        text = page.read_text(encoding="utf-8")
        if "PHYSICS.md" in text:
            problems.append(f"{page.relative_to(source)}: names PHYSICS.md, which is not in the repository")
    return problems


def snapshot(source: Path, build: Path) -> dict[str, tuple[int, float]]:
    """Every file of the source tree but .git, build directories and caches."""
    result = {}
    skip_dirs = {".git", "__pycache__"}
    build = build.resolve()
    for root, dirs, files in os.walk(source):
        rootp = Path(root)
        dirs[:] = [d for d in dirs if d not in skip_dirs and not d.startswith("build")
                   and (rootp / d).resolve() != build]
        for f in files:
            p = rootp / f
            try:
                st = p.lstat()
            except FileNotFoundError:
                continue
            result[str(p.relative_to(source))] = (st.st_size, st.st_mtime)
    return result


def tracked_files(source: Path) -> list[str]:
    """The files of the source tree that git tracks, as they are in the working
    tree (edits included, deleted files left out); without git (a source
    archive), every file but hidden entries and build directories."""
    try:
        listed = subprocess.run(["git", "-C", str(source), "ls-files", "-z", "--cached"],
                                capture_output=True, check=True).stdout.decode()
        names = [n for n in listed.split("\0") if n]
    except (OSError, subprocess.CalledProcessError):
        names = []
        for root, dirs, files in os.walk(source):
            rel = Path(root).relative_to(source)
            dirs[:] = [d for d in dirs if not d.startswith(".") and d != "__pycache__"
                       and not (rel == Path(".") and d.startswith("build"))]
            names += [str(rel / f) for f in files if not f.startswith(".")]
    return [n for n in names if (source / n).is_file() or (source / n).is_symlink()]


def make_scratch(source: Path, build: Path, parent: Path, name: str) -> Path:
    """A copy of the tracked files (a file written by a command lands in the
    copy, whatever the user keeps in the checkout) and build/ -> the build."""
    scratch = Path(tempfile.mkdtemp(prefix=f"{name}-", dir=parent))
    for rel in tracked_files(source):
        dest = scratch / rel
        dest.parent.mkdir(parents=True, exist_ok=True)
        shutil.copy2(source / rel, dest, follow_symlinks=False)
    (scratch / "build").symlink_to(build.resolve())
    return scratch


def block_script(block: Block, status_file: Path, expect: int | None) -> str:
    """bash text that runs the block's commands in order and records, for
    each, its page line and exit code."""
    out = [f"__doc_status() {{ printf '%s %s %s\\n' \"$1\" \"$2\" \"$3\" >> {shlex.quote(str(status_file))}; }}"]
    for n, cmd in enumerate(block.commands):
        last = n == len(block.commands) - 1
        out.append(f"printf '$ %s\\n' {shlex.quote(cmd.text)}; __t=$EPOCHREALTIME")
        out.append(cmd.text)
        status = f"__s=$?; __doc_status {cmd.line} $__s $__t-$EPOCHREALTIME"
        if last and expect is not None:
            out.append(f"{status}; exit 0")
        else:
            out.append(f"{status}; [ $__s -eq 0 ] || exit 100")
    return "\n".join(out) + "\n"


def tail(text: str, n: int = 40) -> str:
    lines = text.rstrip().split("\n")
    cut = lines[-n:]
    prefix = [f"    ... ({len(lines) - n} lines before)"] if len(lines) > n else []
    return "\n".join(prefix + ["    " + l for l in cut])


def run_block(block: Block, scratch: Path, env: dict, timeout: float,
              timings: list[tuple[float, str, str]]) -> str | None:
    """None when the block behaved, else the failure message.  Appends
    (seconds, page:line, command) of each command run to `timings`."""
    if block.lang == "python":
        script = scratch / f".doc_block_{block.line}.py"
        script.write_text("\n".join(block.body) + "\n", encoding="utf-8")
        start = time.monotonic()
        try:
            r = subprocess.run([sys.executable, script.name], cwd=scratch, env=env, stdin=subprocess.DEVNULL,
                               stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True, timeout=timeout)
        except subprocess.TimeoutExpired:
            return f"{block.where()}: python block still running after {timeout:.0f} s"
        timings.append((time.monotonic() - start, block.where(), "python block"))
        if r.returncode != 0:
            return f"{block.where()}: python block exited with {r.returncode}\n{tail(r.stdout)}"
        return None

    expect = None
    if block.marker:
        m = re.fullmatch(r"exit\s+(\d+)", block.marker)
        expect = int(m.group(1)) if m else None
    status = scratch / f".doc_status_{block.line}"
    status.unlink(missing_ok=True)
    script = block_script(block, status, expect)
    try:
        r = subprocess.run(["bash", "-c", script], cwd=scratch, env=env, stdin=subprocess.DEVNULL,
                           stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True, timeout=timeout)
        output = r.stdout
    except subprocess.TimeoutExpired as e:
        out = e.stdout.decode(errors="replace") if isinstance(e.stdout, bytes) else (e.stdout or "")
        done = status.read_text().split("\n") if status.exists() else []
        line = block.commands[min(len([d for d in done if d]), len(block.commands) - 1)].line
        return f"{block.where(line)}: still running after {timeout:.0f} s\n{tail(out)}"
    records = [l.split() for l in status.read_text().splitlines()] if status.exists() else []
    text_of = {c.line: c.text for c in block.commands}
    for rec in records:
        begin, _, end = rec[2].partition("-") if len(rec) > 2 else ("", "", "")
        try:
            seconds = float(end.replace(",", ".")) - float(begin.replace(",", "."))
        except ValueError:
            continue
        timings.append((seconds, block.where(int(rec[0])), text_of.get(int(rec[0]), "")))
    if len(records) < len(block.commands):
        # The shell stopped before the status of a command was recorded.
        line = records[-1][0] if records and records[-1][1] != "0" else block.commands[len(records)].line
        code = records[-1][1] if records and records[-1][1] != "0" else r.returncode
        return f"{block.where(int(line))}: exited with {code}\n{tail(output)}"
    last_line, last_code = int(records[-1][0]), int(records[-1][1])
    if expect is not None and last_code != expect:
        return f"{block.where(last_line)}: exited with {last_code}, the page expects {expect}\n{tail(output)}"
    return None


def collect(source: Path, names: list[str]) -> list[Path]:
    if names:
        return [Path(n).resolve() for n in names]
    return [source / "README.md"] + sorted((source / "docs").glob("*.md"))


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--source", type=Path, required=True, help="the repository root")
    parser.add_argument("--build", type=Path, required=True, help="the build directory (build/friction)")
    parser.add_argument("--work", type=Path, help="where the scratch directories go (default: a temporary directory)")
    parser.add_argument("--keep", action="store_true", help="keep the scratch directories")
    parser.add_argument("--timeout", type=float, default=300.0, help="seconds per block (300)")
    parser.add_argument("--list", action="store_true", help="print what would run and what is skipped, run nothing")
    parser.add_argument("pages", nargs="*", help="pages to run (default: README.md and docs/*.md)")
    args = parser.parse_args(argv)
    source = args.source.resolve()
    build = args.build.resolve()
    if not (build / "friction").is_file():
        parser.error(f"{build}/friction: no program (build first)")

    pages = collect(source, args.pages)
    failures = check_links(source, collect(source, []))
    plan: list[tuple[Path, list[Block]]] = []
    counts = {"run": 0, "expected exit": 0, "not run": 0, "python": 0}
    for page in pages:
        blocks, _, _ = parse_page(page)
        runnable = []
        for b in blocks:
            b.name = str(page.relative_to(source)) if page.is_relative_to(source) else str(page)
            if b.lang in ("sh", "bash", "shell"):
                b.commands = split_commands(b)
                if b.marker is not None and b.marker.startswith("not run"):
                    reason = b.marker.partition(":")[2].strip()
                    if not reason:
                        failures.append(f"{b.where()}: 'not run' needs a reason (<!-- not run: REASON -->)")
                    counts["not run"] += 1
                    if args.list:
                        print(f"{b.where()}: not run ({reason}): " + "; ".join(c.text for c in b.commands))
                    continue
                if b.marker is not None and not re.fullmatch(r"exit\s+\d+", b.marker):
                    failures.append(f"{b.where()}: unknown marker <!-- {b.marker} -->")
                    continue
                if not b.commands:
                    continue
                counts["expected exit" if b.marker else "run"] += 1
                runnable.append(b)
                if args.list:
                    what = f"expects exit {b.marker.split()[1]}" if b.marker else "runs"
                    print(f"{b.where()}: {what}: " + "; ".join(c.text for c in b.commands))
            elif b.lang == "python" and b.marker is not None and re.fullmatch(r"run:\s*python3", b.marker):
                counts["python"] += 1
                runnable.append(b)
                if args.list:
                    print(f"{b.where()}: python block runs")
            elif b.marker is not None and b.lang not in ("sh", "bash", "shell"):
                failures.append(f"{b.where()}: marker <!-- {b.marker} --> on a ```{b.lang or ''} block")
        plan.append((page, runnable))
    if args.list:
        print(f"{counts['run']} blocks run, {counts['expected exit']} expect an error exit, "
              f"{counts['python']} python blocks run, {counts['not run']} not run")
        for f in failures:
            print("FAIL", f)
        return 1 if failures else 0

    env = dict(os.environ)
    env.update(TEST_ENV)
    before = snapshot(source, build)
    work_parent = args.work.resolve() if args.work else Path(tempfile.gettempdir())
    work_parent.mkdir(parents=True, exist_ok=True)
    start_all = time.monotonic()
    timings: list[tuple[float, str, str]] = []
    for page, blocks in plan:
        if not blocks:
            continue
        scratch = make_scratch(source, build, work_parent, page.stem)
        start = time.monotonic()
        page_failures = 0
        try:
            for b in blocks:
                message = run_block(b, scratch, env, args.timeout, timings)
                if message:
                    failures.append(message)
                    page_failures += 1
        finally:
            if not args.keep:
                shutil.rmtree(scratch, ignore_errors=True)
        n = sum(len(b.commands) if b.lang != "python" else 1 for b in blocks)
        print(f"doc-commands: {page.relative_to(source)}: {len(blocks)} blocks, {n} commands, "
              f"{page_failures} failed, {time.monotonic() - start:.1f} s", flush=True)
    after = snapshot(source, build)
    for name in sorted(set(after) - set(before)):
        failures.append(f"the commands left {name} in the source tree")
    for name in sorted(set(before) - set(after)):
        failures.append(f"the commands removed {name} from the source tree")
    for name in sorted(set(before) & set(after)):
        if before[name] != after[name]:
            failures.append(f"the commands changed {name} in the source tree")

    print(f"doc-commands: {time.monotonic() - start_all:.1f} s in all; the slowest commands:")
    for seconds, where, text in sorted(timings, reverse=True)[:5]:
        print(f"    {seconds:6.1f} s  {where}  {text.split(chr(10))[0].split('  #')[0].strip()}")
    for f in failures:
        print(f"doc-commands: FAIL {f}", file=sys.stderr)
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
