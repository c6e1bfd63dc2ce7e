#!/usr/bin/env python3
"""Runs the documentation's commands as a user would (docs/install.md).

    tests/install/runnable_docs.py [--build build/host-release] [--list]

Runs, from the repository root, in one bash shell and in order:
  1. what scripts/bootstrap.sh leaves besides the build: the programs installed in out/gfins
     (cmake --install) and the firmware's candump log out/gfins-fw-rest.log;
  2. every command (each `...` span) of the rows of README.md's "Running things" table that
     carry the marker <!-- runnable -->;
  3. every line of the ```sh blocks of docs/*.md whose preceding line is <!-- runnable -->.
Fails (exit 1) when any of them exits non-zero, naming its file and line; 2 on bad usage or a
marker that does not lead to a command. --list prints the commands without running them.
Cost: about 30 s (the marked rows and blocks are the cheap ones).
"""
import argparse
import os
import pathlib
import re
import subprocess
import sys
import tempfile

MARKER = "<!-- runnable -->"
ROOT = pathlib.Path(__file__).resolve().parents[2]


def readme_rows(path):
    """(where, command) for each `command` of the marked rows of "## Running things"."""
    out = []
    in_section = False
    for n, line in enumerate(path.read_text().splitlines(), 1):
        if line.startswith("## "):
            in_section = line.strip() == "## Running things"
            continue
        if not in_section or not line.startswith("|") or MARKER not in line:
            continue
        cells = [c.strip() for c in line.strip().strip("|").split("|")]
        commands = re.findall(r"`([^`]+)`", cells[-1])
        if not commands:
            raise SystemExit(f"{path.name}:{n}: marked runnable but has no `command`")
        out += [(f"{path.name}:{n}", c) for c in commands]
    return out


def doc_blocks(path):
    """(where, line) for each command line of the fenced sh blocks right after a marker."""
    out = []
    lines = path.read_text().splitlines()
    i = 0
    while i < len(lines):
        if lines[i].strip() != MARKER:
            i += 1
            continue
        where = f"{path.relative_to(ROOT)}:{i + 1}"
        if i + 1 >= len(lines) or not re.match(r"^```(sh|bash|shell)\s*$", lines[i + 1]):
            raise SystemExit(f"{where}: {MARKER} is not followed by a ```sh block")
        i += 2
        pending = ""
        while i < len(lines) and not lines[i].startswith("```"):
            text = lines[i].rstrip()
            i += 1
            if not text or text.lstrip().startswith("#"):
                continue
            if text.endswith("\\"):
                pending += text[:-1] + " "
                continue
            out.append((f"{path.relative_to(ROOT)}:{i}", pending + text))
            pending = ""
    return out


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--build", default="build/host-release")
    ap.add_argument("--list", action="store_true")
    a = ap.parse_args()

    setup = [
        ("bootstrap.sh (install)", f"cmake --install {a.build} --prefix \"$PWD/out/gfins\" >/dev/null"),
        ("bootstrap.sh (main job)",
         f"{a.build}/firmware/app/gfins-fw --sim rest --calibration '' "
         "--can-log out/gfins-fw-rest.log >/dev/null 2>&1"),
    ]
    commands = readme_rows(ROOT / "README.md")
    for doc in sorted((ROOT / "docs").glob("*.md")):
        commands += doc_blocks(doc)
    if not commands:
        raise SystemExit("no command is marked runnable: the marker is " + MARKER)
    if a.list:
        for where, c in setup + commands:
            print(f"{where}: {c}")
        return 0

    # One shell: a row's `export PATH=...` holds for the rows after it. Each command's status is
    # checked; output goes to the log, shown for a failure only.
    script = ["set -o pipefail", "mkdir -p out", "fails=0"]
    for i, (where, c) in enumerate(setup + commands):
        script.append(f"echo '=== {where}' >&2")
        script.append(f"{{ {c}\n}} >\"$RUNNABLE_LOG.{i}\" 2>&1 || {{ rc=$?; "
                      f"echo 'FAIL (exit '$rc'): {where}: {c.replace(chr(39), '')}' >&2; "
                      f"tail -n 15 \"$RUNNABLE_LOG.{i}\" | sed 's/^/    /' >&2; fails=$((fails+1)); }}")
    script.append('[ "$fails" = 0 ] || { echo "runnable_docs: $fails command(s) failed" >&2; exit 1; }')
    with tempfile.TemporaryDirectory(prefix="gfins-docs-") as tmp:
        env = dict(os.environ, RUNNABLE_LOG=str(pathlib.Path(tmp) / "log"))
        rc = subprocess.run(["bash", "-c", "\n".join(script)], cwd=ROOT, env=env).returncode
    if rc == 0:
        print(f"runnable_docs: {len(commands)} documented command(s) ran with exit status 0")
    return 1 if rc != 0 else 0


if __name__ == "__main__":
    sys.exit(main())
