#!/usr/bin/env python3
"""The documentation stands alone ("Docs"): every link and file path a Markdown file
of the repository names resolves to a file inside the repository, and nothing refers to
material a user of the project does not have (the development notes, design and style guides
kept outside the repository, absolute paths of a development machine).

Checked, in README.md and docs/*.md (and every other tracked *.md outside node_modules):
  - Markdown links and images `[text](target)`: a relative target must exist inside the
    repository (anchors and URLs with a scheme are not files and are skipped);
  - any `../` path that climbs out of the repository, in links or in text;
  - names of the outside material: `shared/`, `DESIGN.md`, `STYLE.md`, `/work/`.
Exit status 1 with one line per finding (file:line: what), 0 when clean.
"""
import pathlib
import re
import subprocess
import sys

REPO = pathlib.Path(__file__).resolve().parents[2]
LINK = re.compile(r"!?\[[^\]]*\]\(([^)\s]+)(?:\s+\"[^\"]*\")?\)")
OUTSIDE_WORDS = re.compile(r"(?<![\w./-])(?:\.\./)*shared/|\bDESIGN\.md\b|\bSTYLE\.md\b|(?<![\w.])/work/")
CLIMB = re.compile(r"(?:\.\./)+[\w.-]+")


def tracked_markdown():
    out = subprocess.run(["git", "-C", str(REPO), "ls-files", "*.md"], capture_output=True,
                         text=True, check=False)
    if out.returncode == 0 and out.stdout.strip():
        names = out.stdout.split("\n")
    else:  # an exported tree without .git: every *.md under the repository
        names = [str(p.relative_to(REPO)) for p in REPO.rglob("*.md")]
    return [REPO / n for n in names if n and "node_modules" not in n]


def inside(path):
    try:
        path.resolve().relative_to(REPO)
        return True
    except ValueError:
        return False


def check(md):
    problems = []
    rel = md.relative_to(REPO)
    for no, line in enumerate(md.read_text(encoding="utf-8").splitlines(), 1):
        for m in LINK.finditer(line):
            target = m.group(1)
            if re.match(r"^[a-z][a-z0-9+.-]*:", target) or target.startswith("#"):
                continue
            path = target.split("#", 1)[0]
            if not path:
                continue
            resolved = (REPO / path.lstrip("/")) if path.startswith("/") else (md.parent / path)
            if not inside(resolved):
                problems.append(f"{rel}:{no}: link '{target}' leaves the repository")
            elif not resolved.exists():
                problems.append(f"{rel}:{no}: link '{target}' names no file of the repository")
        for m in CLIMB.finditer(line):
            if not inside(md.parent / m.group(0)):
                problems.append(f"{rel}:{no}: path '{m.group(0)}' leaves the repository")
        for m in OUTSIDE_WORDS.finditer(line):
            problems.append(f"{rel}:{no}: '{m.group(0)}' names material outside the repository")
    return problems


def main():
    files = tracked_markdown()
    if len(files) < 2:
        print(f"stand_alone_test: found {len(files)} Markdown file(s) under {REPO}", file=sys.stderr)
        return 1
    problems = [p for md in files for p in check(md)]
    for p in problems:
        print(p)
    print(f"stand_alone_test: {len(files)} Markdown files, {len(problems)} problem(s)")
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
