#!/usr/bin/python3
"""Checks the documentation: README.md is the landing page, docs/readme/*.md the pages it links.

  - README.md's first section (the one after the title) holds exactly the two commands `make demo`, `make test`;
  - every page docs/readme/*.md is linked from README.md;
  - every relative link in README.md, docs/*.md and docs/readme/*.md names a file that exists.

usage: check_docs.py      exit 1 with one line per problem
"""
import glob
import os
import re
import sys

ROOT = os.path.normpath(os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
LINK = re.compile(r"\[[^\]]*\]\(([^)\s]+)\)")


def problems():
    out = []
    readme = os.path.join(ROOT, "README.md")
    with open(readme) as f:
        text = f.read()
    sections = re.split(r"^## ", text, flags=re.M)
    first = sections[1] if len(sections) > 1 else ""
    commands = [l.split("#")[0].strip() for l in re.findall(r"```bash\n(.*?)```", first, flags=re.S)[0].splitlines()] \
        if "```bash" in first else []
    commands = [c for c in commands if c]
    if commands != ["make demo", "make test"]:
        out.append("README.md: the first section must hold exactly `make demo` and `make test`, found %s" % commands)
    for page in sorted(glob.glob(os.path.join(ROOT, "docs", "readme", "*.md"))):
        rel = os.path.relpath(page, ROOT)
        if "(" + rel + ")" not in text and "(" + rel + "#" not in text:
            out.append("README.md does not link the page %s" % rel)
    files = [readme] + glob.glob(os.path.join(ROOT, "docs", "*.md")) + glob.glob(os.path.join(ROOT, "docs", "readme", "*.md"))
    for path in files:
        with open(path) as f:
            for n, line in enumerate(f, 1):
                for target in LINK.findall(line):
                    if re.match(r"^[a-z]+://", target) or target.startswith("#") or target.startswith("mailto:"):
                        continue
                    file_part = target.split("#")[0]
                    if not os.path.exists(os.path.normpath(os.path.join(os.path.dirname(path), file_part))):
                        out.append("%s:%d: link to %s: no such file" % (os.path.relpath(path, ROOT), n, target))
    return out


def main():
    found = problems()
    for p in found:
        print(p)
    if not found:
        print("docs: README.md links every page, every link resolves")
    return 1 if found else 0


if __name__ == "__main__":
    sys.exit(main())
