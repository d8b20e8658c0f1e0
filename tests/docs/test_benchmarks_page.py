"""docs/benchmarks.md names exactly the RATIO figures the benchmarks print.

The names are read from the bench sources (bench/**/*.cc, *.sh, *.py), not from a list kept by
hand: every string literal that starts with "RATIO " is a template. Its name part is resolved
  - as it is when it holds no placeholder;
  - through the calls of the helper it sits in (Ratio("caliper_vs_raw_bullet", ...) for a
    Ratio(const char* name, ...) that prints "RATIO %s ...");
  - through a table of cases when the name comes from a struct field (c.name, c.ratio): the
    brace initializers with as many elements as the struct has fields;
  - else as a pattern (a placeholder matches a word, a number or a bracketed run), which the page
    must match with at least one name.
The page's names are the code spans in the first column of its tables headed "RATIO name".
"""

import pathlib
import re

ROOT = pathlib.Path(__file__).resolve().parents[2]
PAGE = ROOT / "docs" / "benchmarks.md"
BENCH = ROOT / "bench"

# printf conversions, Python f-string fields and shell expansions
PLACEHOLDER = re.compile(r"%[-+ #0]*\d*(?:\.\d+)?(?:l|ll|z|h)?[sdifgeuxc]|\{[^{}]*\}|\$\{?\w+\}?")


def bench_sources():
    return sorted(p for p in BENCH.rglob("*") if p.suffix in (".cc", ".sh", ".py") and p.is_file())


def strip_cc_comments(text):
    """C++ text with // and /* */ comments blanked (string literals kept)."""
    out, i, n = [], 0, len(text)
    while i < n:
        c = text[i]
        if c == '"':
            j = i + 1
            while j < n and text[j] != '"':
                j += 2 if text[j] == "\\" else 1
            out.append(text[i:j + 1])
            i = j + 1
        elif c == "'" and i + 2 < n:
            j = text.find("'", i + 1 if text[i + 1] != "\\" else i + 2)
            if j < 0:  # an apostrophe in a comment or a stray one: the rest is plain text
                out.append(text[i:])
                break
            out.append(text[i:j + 1])
            i = j + 1
        elif text.startswith("//", i):
            j = text.find("\n", i)
            j = n if j < 0 else j
            out.append(" " * (j - i))
            i = j
        elif text.startswith("/*", i):
            j = text.find("*/", i + 2)
            j = n if j < 0 else j + 2
            out.append(re.sub(r"[^\n]", " ", text[i:j]))
            i = j
        else:
            out.append(c)
            i += 1
    return "".join(out)


def name_part(template):
    """The name after 'RATIO ': up to the first blank outside brackets and placeholders."""
    depth, k = 0, 0
    while k < len(template):
        m = PLACEHOLDER.match(template, k)
        if m:
            k = m.end()
            continue
        ch = template[k]
        if ch == "[":
            depth += 1
        elif ch == "]":
            depth -= 1
        elif ch in " \\\t" and depth == 0:
            break
        k += 1
    return template[:k]


def to_regex(name):
    parts, k = [], 0
    for m in PLACEHOLDER.finditer(name):
        parts.append(re.escape(name[k:m.start()]))
        parts.append(r"[\w.@, -]+")
        k = m.end()
    parts.append(re.escape(name[k:]))
    return "".join(parts)


def enclosing_function(text, pos, python):
    """The name of the function whose body holds pos (the nearest definition before it)."""
    if python:
        defs = list(re.finditer(r"^\s*def\s+(\w+)\s*\(", text[:pos], re.M))
    else:
        defs = list(re.finditer(r"^[A-Za-z_][\w:<>,\s\*&]*?\b(\w+)\s*\([^;{}]*\)\s*(?:const\s*)?\{",
                                text[:pos], re.M))
    return defs[-1].group(1) if defs else None


def helper_call_names(text, function):
    return [m.group(1) for m in re.finditer(r"(?<![\w.])" + re.escape(function) + r'\(\s*"([^"]*)"',
                                             text)]


def string_end(text, i):
    """The index of the quote that closes the C++ string literal opening at text[i]."""
    i += 1
    while i < len(text) and text[i] != '"':
        i += 2 if text[i] == "\\" else 1
    return i


def top_level_split(body):
    """Elements of a brace initializer's body, split at top-level commas."""
    items, depth, start, i = [], 0, 0, 0
    while i < len(body):
        c = body[i]
        if c == '"':
            i = string_end(body, i)
        elif c in "{([":
            depth += 1
        elif c in "})]":
            depth -= 1
        elif c == "," and depth == 0:
            items.append(body[start:i].strip())
            start = i + 1
        i += 1
    last = body[start:].strip()
    if last:
        items.append(last)
    return items


def brace_groups(text):
    stack, groups, i = [], [], 0
    while i < len(text):
        c = text[i]
        if c == '"':
            i = string_end(text, i)
        elif c == "{":
            stack.append(i)
        elif c == "}" and stack:
            groups.append(text[stack.pop() + 1:i])
        i += 1
    return groups


def table_names(text, statement):
    """Names from a case table when the template's first argument is a struct field (c.name)."""
    m = re.search(r"\b\w+\.(\w+)\b", statement.split(",", 1)[1] if "," in statement else "")
    if not m:
        return []
    field = m.group(1)
    for s in re.finditer(r"struct\s+\w+\s*\{(.*?)\n\};", text, re.S):
        # data members, in order (comments are blanked already; a member function ends in ')')
        members = [x.strip() for x in s.group(1).split(";")]
        members = [x for x in members if x and not re.search(r"\)\s*(const)?$", x)]
        index = [k for k, x in enumerate(members) if re.search(r"\b" + field + r"\s*(=.*)?$", x)]
        if not index:
            continue
        k, n = index[0], len(members)
        names = []
        for g in brace_groups(text):
            items = top_level_split(g)
            if len(items) == n and re.fullmatch(r'"[^"]*"', items[k]):
                names.append(items[k][1:-1])
        return names
    return []


def printed_names():
    """(concrete names, patterns, unresolved templates), each with the file it comes from."""
    names, patterns, unresolved = {}, {}, []
    for path in bench_sources():
        raw = path.read_text(encoding="utf-8")
        python = path.suffix == ".py"
        text = strip_cc_comments(raw) if path.suffix == ".cc" else raw
        for m in re.finditer(r'(?:f)?"RATIO ([^"\n]*)', text):
            if path.suffix != ".cc":  # a shell or Python comment line is no print
                line = text[text.rfind("\n", 0, m.start()) + 1:m.start()]
                if line.lstrip().startswith("#"):
                    continue
            name = name_part(m.group(1))
            rel = str(path.relative_to(ROOT))
            if not PLACEHOLDER.search(name):
                names.setdefault(name, rel)
                continue
            resolved = []
            function = enclosing_function(text, m.start(), python)
            if function and function != "main":
                for arg in helper_call_names(text, function):
                    resolved.append(PLACEHOLDER.sub(arg, name, count=1))
            if not resolved:
                end = text.find(";", m.start()) if not python else text.find("\n", m.start())
                resolved = [PLACEHOLDER.sub(x, name, count=1) for x in
                            table_names(text, text[m.start():end])]
            if resolved and not any(PLACEHOLDER.search(r) for r in resolved):
                for r in resolved:
                    names.setdefault(r, rel)
            elif PLACEHOLDER.fullmatch(name):
                unresolved.append(f"{rel}: RATIO {name}")
            else:
                patterns.setdefault(to_regex(name), (name, rel))
    return names, patterns, unresolved


def page_names():
    names, in_table = [], False
    for line in PAGE.read_text(encoding="utf-8").splitlines():
        cells = [c.strip() for c in line.strip().strip("|").split("|")] if line.startswith("|") else None
        if cells is None:
            in_table = False
            continue
        if not in_table:
            in_table = cells[0] == "RATIO name"
            header = True
            continue
        if header and set(cells[0]) <= set("-: "):
            header = False
            continue
        span = re.match(r"`([^`]+)`", cells[0])
        assert span, f"docs/benchmarks.md: a RATIO table row without a `name` first: {line}"
        names.append(span.group(1))
    return names


def test_sources_yield_names():
    names, patterns, unresolved = printed_names()
    assert not unresolved, ("RATIO templates whose name this test cannot resolve (give the name a "
                            "literal, a helper call or a case table):\n  " + "\n  ".join(unresolved))
    # a sanity floor: the benches print dozens of figures
    assert len(names) + len(patterns) >= 30, sorted(names)


def test_every_printed_name_is_on_the_page():
    names, patterns, _ = printed_names()
    documented = page_names()
    missing = [f"{n}  ({src})" for n, src in sorted(names.items()) if n not in documented]
    missing += [f"{shown}  (pattern, {src})" for rx, (shown, src) in sorted(patterns.items())
                if not any(re.fullmatch(rx, d) for d in documented)]
    assert not missing, ("printed by a bench but missing from docs/benchmarks.md:\n  " +
                         "\n  ".join(missing))


def test_every_name_on_the_page_is_printed():
    names, patterns, _ = printed_names()
    documented = page_names()
    assert documented, "docs/benchmarks.md has no table headed 'RATIO name'"
    unknown = [d for d in documented
               if d not in names and not any(re.fullmatch(rx, d) for rx in patterns)]
    assert not unknown, ("named in docs/benchmarks.md but printed by no bench:\n  " +
                         "\n  ".join(unknown))


def test_no_name_twice_on_the_page():
    documented = page_names()
    twice = sorted({d for d in documented if documented.count(d) > 1})
    assert not twice, f"named twice in docs/benchmarks.md: {twice}"


def test_page_has_a_section_per_bench_verb():
    text = PAGE.read_text(encoding="utf-8")
    verbs = re.search(r"bench\) cmd_bench|physics\|collada\|model\|gui\|cluster\|calibration\|python\|slurm",
                      (ROOT / "launch" / "dev_verbs.sh").read_text(encoding="utf-8"))
    assert verbs
    for verb in ("physics", "collada", "model", "gui", "cluster", "calibration", "python", "slurm"):
        assert re.search(rf"^## {verb}$", text, re.M), f"docs/benchmarks.md lacks '## {verb}'"


if __name__ == "__main__":
    n, p, u = printed_names()
    for name, src in sorted(n.items()):
        print(f"{name}\t{src}")
    for rx, (shown, src) in sorted(p.items()):
        print(f"{shown}\t{src}\t(pattern)")
    for x in u:
        print(f"UNRESOLVED {x}")
