#!/usr/bin/env python3
"""Lists the functions of Caliper's own code longer than a bound, as clang parses them.

Reads the build's compile_commands.json, parses each source file under the given folders with
libclang (Debian python3-clang-14) and measures every function, method, constructor, lambda-free
definition from its first line to its closing brace. Function bodies in headers are measured
where a source under the folders includes them. Data tables (functions that only fill a table of
numbers) may be named with --allow NAME. Exit 0 when none is longer than --max-lines, 1 otherwise,
77 when libclang or the compile database is missing.

  python3 tests/layout/function_length.py --build build --max-lines 150 libs components
"""
import argparse
import json
import os
import shlex
import sys
from concurrent.futures import ProcessPoolExecutor

KINDS = ("FUNCTION_DECL", "CXX_METHOD", "CONSTRUCTOR", "DESTRUCTOR", "FUNCTION_TEMPLATE",
         "CONVERSION_FUNCTION")


_CLANG = None


def load_clang():
    global _CLANG
    if _CLANG is not None:
        return _CLANG
    try:
        sys.path.insert(0, "/usr/lib/python3/dist-packages")
        import clang.cindex as ci
    except ImportError:
        return None
    for lib in ("/usr/lib/x86_64-linux-gnu/libclang-14.so.1", "/usr/lib/llvm-14/lib/libclang.so.1"):
        if os.path.exists(lib):
            ci.Config.set_library_file(lib)
            _CLANG = ci
            return ci
    return None


def measure(job):
    """[(file, first line, last line, qualified name)] of the definitions in one source."""
    source, args, roots = job
    ci = load_clang()
    index = ci.Index.create()
    tu = index.parse(source, args=args,
                     options=ci.TranslationUnit.PARSE_INCOMPLETE)
    kinds = {getattr(ci.CursorKind, k) for k in KINDS}
    out = []

    def walk(cursor):
        for c in cursor.get_children():
            loc = c.location.file
            if loc is None or not any(loc.name.startswith(r) for r in roots):
                continue
            if c.kind in kinds and c.is_definition():
                start, end = c.extent.start.line, c.extent.end.line
                name = c.spelling
                p = c.semantic_parent
                while p is not None and p.kind != ci.CursorKind.TRANSLATION_UNIT:
                    if p.spelling:
                        name = p.spelling + "::" + name
                    p = p.semantic_parent
                out.append((loc.name, start, end, name))
            walk(c)

    walk(tu.cursor)
    return out


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--build", required=True)
    parser.add_argument("--source", default=os.getcwd())
    parser.add_argument("--max-lines", type=int, default=150)
    parser.add_argument("--allow", action="append", default=[], help="a data table's name")
    parser.add_argument("--jobs", type=int, default=os.cpu_count() or 1)
    parser.add_argument("folders", nargs="+")
    a = parser.parse_args()
    if load_clang() is None:
        print("skipped: libclang for Python (python3-clang-14) is not installed")
        return 77
    db_path = os.path.join(a.build, "compile_commands.json")
    if not os.path.exists(db_path):
        print("skipped: no " + db_path)
        return 77
    source = os.path.realpath(a.source)
    roots = [os.path.join(source, f) + "/" for f in a.folders]
    jobs = []
    for entry in json.load(open(db_path)):
        path = os.path.realpath(os.path.join(entry["directory"], entry["file"]))
        if not any(path.startswith(r) for r in roots):
            continue
        words = shlex.split(entry["command"])[1:]
        args, skip = [], False
        for w in words:
            if skip:
                skip = False
                continue
            if w in ("-o", "-MF", "-MT", "-c"):
                skip = w != "-c"
                continue
            if w == path or w.endswith(entry["file"]) or w.startswith("-W") or w.startswith("-f"):
                continue
            args.append(w if not w.startswith("-I") or os.path.isabs(w[2:])
                        else "-I" + os.path.join(entry["directory"], w[2:]))
        jobs.append((path, args + ["-Wno-everything"], roots))
    found = {}
    with ProcessPoolExecutor(max_workers=a.jobs) as pool:
        for result in pool.map(measure, jobs):
            for f, start, end, name in result:
                found[(f, start)] = (end - start + 1, name, f, start)
    long = sorted((v for v in found.values() if v[0] > a.max_lines and
                   not any(v[1].endswith(x) for x in a.allow)), reverse=True)
    print("%d sources parsed, %d function definitions measured; longest: %s" % (
        len(jobs), len(found),
        ", ".join("%s %d" % (v[1], v[0]) for v in sorted(found.values(), reverse=True)[:5])))
    for n, name, f, start in long:
        print("TOO LONG: %s:%d %s: %d lines (at most %d)" % (os.path.relpath(f, source), start, name,
                                                           n, a.max_lines))
    return 1 if long else 0


if __name__ == "__main__":
    sys.exit(main())
