"""Checks that every fenced code block of a Markdown page is quoted from the given files.

    doc_quotes.py PAGE.md FILE [FILE ...]

A block passes when its lines, each stripped of leading and trailing blanks,
appear as consecutive lines (stripped the same way) of one of the files, so
a page may quote an indented excerpt without its indentation. Exits 1 naming
the page, the block's first line number and its first line when a block is
not found, or when the page has no code block at all.
"""
import sys


def blocks(lines):
    start, body = None, []
    for number, line in enumerate(lines, 1):
        if line.lstrip().startswith("```"):
            if start is None:
                start, body = number, []
            else:
                yield start, body
                start = None
        elif start is not None:
            body.append(line.strip())
    if start is not None:
        raise SystemExit(f"{sys.argv[1]}, line {start}: code block never closed")


def contains(haystack, needle):
    return any(haystack[i:i + len(needle)] == needle for i in range(len(haystack) - len(needle) + 1))


def main():
    if len(sys.argv) < 3:
        raise SystemExit(__doc__)
    page = open(sys.argv[1], encoding="utf-8").read().splitlines()
    sources = {path: [line.strip() for line in open(path, encoding="utf-8").read().splitlines()]
               for path in sys.argv[2:]}
    found = failed = 0
    for start, body in blocks(page):
        found += 1
        if not any(contains(lines, body) for lines in sources.values()):
            failed += 1
            print(f"{sys.argv[1]}, line {start}: code block not found in {', '.join(sources)}: "
                  f"{body[0] if body else '(empty)'}")
    if found == 0:
        print(f"{sys.argv[1]}: no code block")
        return 1
    print(f"{found - failed} of {found} code blocks of {sys.argv[1]} quoted from the examples")
    return 1 if failed else 0


sys.exit(main())
