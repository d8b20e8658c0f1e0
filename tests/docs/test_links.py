"""Every link between Caliper's pages leads somewhere: the file exists and, when the link names
a section (#anchor), the page has a heading with that anchor (GitHub's rule: lower case, spaces
to '-', punctuation dropped). Covers README.md and docs/**/*.md; links to the web are not
followed (no network in CI)."""

import glob
import os
import re

ROOT = os.environ.get("CALIPER_SOURCE_DIR",
                      os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__)))))

LINK = re.compile(r"\[[^\]]*\]\(([^)\s]+)\)")
FENCE = re.compile(r"^(```|````)")


def pages():
    found = [os.path.join(ROOT, "README.md"), os.path.join(ROOT, "CHANGELOG.md")]
    found += sorted(glob.glob(os.path.join(ROOT, "docs", "**", "*.md"), recursive=True))
    return found


def prose(path):
    """The page's lines outside fenced blocks, with their numbers."""
    inside = None
    for number, line in enumerate(open(path, encoding="utf-8"), 1):
        m = FENCE.match(line)
        if m:
            if inside is None:
                inside = m.group(1)
            elif m.group(1) == inside:
                inside = None
            continue
        if inside is None:
            yield number, line


def slug(heading):
    text = re.sub(r"`|\*\*|\*", "", heading.strip()).lower()
    text = re.sub(r"\[([^\]]*)\]\([^)]*\)", r"\1", text)  # a link in a heading: its text
    text = re.sub(r"[^\w\- ]", "", text)
    return text.replace(" ", "-")


def anchors(path):
    seen = {}
    result = set()
    for _, line in prose(path):
        m = re.match(r"^#{1,6}\s+(.*?)\s*#*\s*$", line)
        if not m:
            continue
        base = slug(m.group(1))
        n = seen.get(base, 0)
        seen[base] = n + 1
        result.add(base if n == 0 else f"{base}-{n}")
    for m in re.finditer(r'<a (?:name|id)="([^"]+)"', open(path, encoding="utf-8").read()):
        result.add(m.group(1))
    return result


def broken_links():
    problems = []
    for page in pages():
        for number, line in prose(page):
            for target in LINK.findall(re.sub(r"`[^`]*`", "", line)):
                if re.match(r"^[a-z]+:", target):  # https:, mailto:
                    continue
                path, _, anchor = target.partition("#")
                where = os.path.normpath(os.path.join(os.path.dirname(page), path)) if path else page
                name = f"{os.path.relpath(page, ROOT)}:{number}: {target}"
                if not os.path.exists(where):
                    problems.append(f"{name}: no file {os.path.relpath(where, ROOT)}")
                elif anchor and where.endswith(".md") and anchor not in anchors(where):
                    problems.append(f"{name}: {os.path.relpath(where, ROOT)} has no section #{anchor}")
    return problems


def test_the_pages_link_to_what_exists():
    problems = broken_links()
    assert not problems, "broken links:\n  " + "\n  ".join(problems)


def test_the_check_sees_a_broken_link(tmp_path):
    page = tmp_path / "page.md"
    page.write_text("# A page\n\n## Two words\n\n[ok](#two-words) [gone](#three) [none](nothing.md)\n")
    assert anchors(str(page)) == {"a-page", "two-words"}
    global ROOT
    saved, ROOT = ROOT, str(tmp_path)
    try:
        os.makedirs(tmp_path / "docs")
        (tmp_path / "README.md").write_text("[p](page.md#two-words) [q](page.md#three)\n")
        (tmp_path / "CHANGELOG.md").write_text("")
        problems = broken_links()
    finally:
        ROOT = saved
    assert any("README.md:1: page.md#three" in p for p in problems), problems
    assert not any("page.md#two-words" in p for p in problems), problems
