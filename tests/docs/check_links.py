"""Every relative link of the project's Markdown resolves: the file (or folder) it names exists, and
the heading its #anchor names is in that file (GitHub's anchors: lowercase, punctuation dropped,
spaces to hyphens). Links in code blocks and inline code are not links; web addresses are not
checked (the tests run offline).

    python3 check_links.py SOURCE_DIR
"""
import pathlib
import re
import sys

LINK = re.compile(r"!?\[[^\]]*\]\(([^)\s]+)(?:\s+\"[^\"]*\")?\)")
HEADING = re.compile(r"^#{1,6}\s+(.*?)\s*#*\s*$")
SKIPPED_DIRS = {"build", "node_modules", ".git", "dist"}


def markdown_files(root):
    for path in sorted(root.rglob("*.md")):
        if not SKIPPED_DIRS.intersection(path.relative_to(root).parts):
            yield path


def prose_lines(text):
    """(line number, line) outside fenced code blocks, with inline code removed."""
    fenced = False
    for number, line in enumerate(text.splitlines(), 1):
        if line.lstrip().startswith("```"):
            fenced = not fenced
            continue
        if not fenced:
            yield number, re.sub(r"`[^`]*`", "", line)


def anchor(heading):
    heading = re.sub(r"[^\w\- ]", "", heading.replace("`", "").strip().lower())
    return heading.replace(" ", "-")


def anchors(path):
    """The anchors of a file's headings (their inline code kept: its text is part of the anchor)."""
    fenced, names = False, set()
    for line in path.read_text(encoding="utf-8").splitlines():
        if line.lstrip().startswith("```"):
            fenced = not fenced
        elif not fenced and HEADING.match(line):
            base = anchor(HEADING.match(line).group(1))
            name, n = base, 1
            while name in names:  # a repeated heading gets -1, -2, ...
                name, n = f"{base}-{n}", n + 1
            names.add(name)
    return names


def check(root):
    problems = []
    for md in markdown_files(root):
        for number, line in prose_lines(md.read_text(encoding="utf-8")):
            for target in LINK.findall(line):
                if re.match(r"^[a-z]+:", target):
                    continue
                file_part, _, fragment = target.partition("#")
                linked = (md.parent / file_part).resolve() if file_part else md
                where = f"{md.relative_to(root)}:{number}: link '{target}'"
                if not linked.exists():
                    problems.append(f"{where}: {file_part} does not exist")
                elif fragment and linked.suffix == ".md":
                    if fragment not in anchors(linked):
                        problems.append(f"{where}: {linked.relative_to(root)} has no heading with the anchor #{fragment}")
    return problems


def main():
    root = pathlib.Path(sys.argv[1]).resolve()
    problems = check(root)
    for problem in problems:
        print("FAIL " + problem)
    count = sum(1 for _ in markdown_files(root))
    print(f"{count} Markdown files, {len(problems)} broken links")
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
