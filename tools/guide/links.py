#!/usr/bin/env python3
"""Checks the links of the guide's sources (tools/guide/build.sh runs it).

    python3 tools/guide/links.py docs/guide

Every chapter must be listed in SUMMARY.md and every file SUMMARY.md lists must exist. A
relative link (Markdown `[text](target)` or `![alt](target)`, or an HTML `src`/`href`) must name
a file that exists: a chapter or an image of the book, or a file of the repository out of it
(docs/formats.md, ARCHITECTURE.md). Its `#anchor`, in a Markdown file, must be one of that
file's headings, as mdBook and GitHub spell them. Links to other
sites are not fetched. Exits 1 naming every broken link.
"""
import pathlib
import re
import sys

book = pathlib.Path(sys.argv[1]).resolve()
src = book / "src"
repo = pathlib.Path(__file__).resolve().parents[2]


def strip_code(text):
    """The text without fenced blocks and inline code, lines kept."""
    text = re.sub(r"^```.*?^```", lambda m: "\n" * m.group(0).count("\n"), text, flags=re.S | re.M)
    return re.sub(r"`[^`\n]*`", "", text)


def slug(heading):
    """A heading's anchor as mdBook (normalize_id) and GitHub both spell it: lower case,
    alphanumerics, '_' and '-' kept, each space a '-', the rest dropped."""
    out = []
    for c in heading.strip().lower():
        if c.isalnum() or c in "_-":
            out.append(c)
        elif c == " ":
            out.append("-")
    return "".join(out)


def headings(path):
    text = path.read_text()
    text = re.sub(r"^```.*?^```", "", text, flags=re.S | re.M)
    ids, seen = set(), {}
    for title in re.findall(r"^#{1,6}\s+(.*?)\s*#*\s*$", text, flags=re.M):
        plain = re.sub(r"\[([^\]]*)\]\([^)]*\)", r"\1", title).replace("`", "")
        base = slug(plain)
        n = seen.get(base, 0)
        seen[base] = n + 1
        ids.add(base if n == 0 else f"{base}-{n}")
    return ids


errors = []
summary = (src / "SUMMARY.md").read_text()
listed = {(src / t).resolve() for t in re.findall(r"\]\(([^)#]+\.md)\)", summary)}
for path in listed:
    if not path.is_file():
        errors.append(f"SUMMARY.md: {path.relative_to(src)} does not exist")
chapters = sorted(p for p in src.rglob("*.md") if p.name != "SUMMARY.md")
for path in chapters:
    if path.resolve() not in listed:
        errors.append(f"{path.relative_to(src)}: not listed in SUMMARY.md")

link = re.compile(r"!?\[(?:[^\]\[]|\[[^\]]*\])*\]\(([^)\s]+)(?:\s+\"[^\"]*\")?\)|(?:src|href)=\"([^\"]+)\"")
count = 0
for path in [src / "SUMMARY.md", *chapters]:
    lines = strip_code(path.read_text()).split("\n")
    for number, line in enumerate(lines, 1):
        for m in link.finditer(line):
            target = m.group(1) or m.group(2)
            if re.match(r"^[a-z][a-z0-9+.-]*:", target):  # https:, mailto:
                continue
            count += 1
            where = f"{path.relative_to(src)}:{number}: {target}"
            file, _, anchor = target.partition("#")
            dest = (path.parent / file).resolve() if file else path.resolve()
            if not dest.exists():
                errors.append(f"{where}: no such file")
                continue
            try:
                dest.relative_to(repo)
            except ValueError:
                errors.append(f"{where}: outside the repository")
                continue
            if anchor and dest.suffix == ".md":
                if anchor not in headings(dest):
                    errors.append(f"{where}: no heading '#{anchor}' in {dest.relative_to(repo)}")
            if file and src not in dest.parents and dest.suffix != ".md":
                # An image or other file the HTML book must carry has to be inside src/.
                errors.append(f"{where}: a file out of the book is not copied into it (put it under {src.relative_to(repo)})")

if errors:
    print("\n".join(f"guide: broken link: {e}" for e in errors))
    print(f"guide: FAILED: {len(errors)} broken links")
    sys.exit(1)
print(f"guide: {count} links checked in {len(chapters)} chapters")
