#!/usr/bin/env python3
"""The rules of Caliper's layout, checked on what the build recorded.

docs/architecture.md ("Rules the layout keeps") states them.

Two sources, both written by the build, never guessed from the sources:

  headers  `ninja -C BUILD -t deps`: for every object file, every header its compilation read
           (directly or through other headers)
  links    CMake's File API (codemodel-v2) in BUILD/.cmake/api/v1/reply/: every target, the
           folder that defines it and the targets it depends on (tests/layout/CMakeLists.txt
           writes the query at configure time; CMake answers it at the next configure)

Rules (a target or object belongs to the folder whose CMakeLists.txt defines its target):
  1. components are leaves: no object of components/X includes a header under components/Y
     (Y != X), and no target of components/X depends, directly or through others, on a target
     defined in components/Y
  2. libraries never see components: no object of libs/ includes a header under components/, no
     target of libs/ depends on a target of components/
  3. third-party engines stay in their adapter: only objects of libs/physics_bullet read Bullet's
     headers, only libs/collada Collada-DOM's, only libs/render_coin Coin3D's (through any
     header, so a public header that leaks one fails here); libs/sgal, libs/actuators and libs/daq
     read no CORBA, no Qt and no engine header; of the libraries only libs/rtc and libs/client (and
     what links libs/client: libs/calibration's evaluator) read generated IDL headers
The Python package's extension (python/) is a client like the components: rule 1 holds for it
too (it reads no component's header and links no component's target).
Targets under tests/, bench/ and fuzz/ may use anything: they are not components.

Exit status: 0 all rules hold, 1 a rule is broken (each violation printed), 77 skipped (the build
tree lacks what is read; the reason is printed), 2 bad usage.
Options --deps-file and --file-api-reply read saved or hand-made data instead (to test this test).
"""

import argparse
import glob
import json
import os
import re
import shlex
import subprocess
import sys

SKIP = 77

# rule 3: (name, predicate on a header's absolute path, owners allowed to read it)
GENERATED_IDL = re.compile(r"/idl/caliper/[^/]+\.hh$")
ENGINE_HEADERS = [
    ("Bullet", lambda p: p.startswith("/usr/include/bullet/"), {"libs/physics_bullet"}),
    ("Collada-DOM", lambda p: p.startswith("/usr/include/collada-dom"), {"libs/collada"}),
    ("Coin3D", lambda p: p.startswith("/usr/include/Inventor/"), {"libs/render_coin"}),
]
# libraries that know no CORBA, no Qt and no engine
PLAIN_LIBRARIES = {"libs/sgal", "libs/actuators", "libs/daq"}
PLAIN_FORBIDDEN = [
    ("omniORB", lambda p: "/omniORB4/" in p or "/omnithread" in p),
    ("Qt", lambda p: "/qt5/" in p),
    ("Bullet", lambda p: p.startswith("/usr/include/bullet/")),
    ("Coin3D", lambda p: p.startswith("/usr/include/Inventor/")),
    ("Collada-DOM", lambda p: p.startswith("/usr/include/collada-dom")),
]
# the library targets that may read generated IDL headers (the evaluator through client's headers)
IDL_TARGETS = {"caliper_rtc", "caliper_client", "caliper_calibration_evaluator"}
EXEMPT_TOPS = ("tests", "bench", "fuzz")


def owner_of(folder):
    """'components/ctl' for components/ctl/..., 'libs/sgal' for libs/sgal/..., else None."""
    parts = folder.split("/")
    if parts[0] == "python":
        return "python"
    if len(parts) >= 2 and parts[0] in ("components", "libs"):
        return parts[0] + "/" + parts[1]
    return None


def kind_of(folder):
    top = folder.split("/")[0]
    if top in ("components", "libs"):
        return top
    if top == "python":
        return "components"  # a client: a leaf like the components
    if top in EXEMPT_TOPS:
        return "exempt"
    return "other"


class Tree:
    def __init__(self, source, build):
        self.source = os.path.realpath(source)
        self.build = os.path.realpath(build)

    def where(self, path):
        """('build' | 'source' | 'system', path relative to that root) for a path from the deps
        log (relative paths start from the build directory)."""
        p = os.path.normpath(path if os.path.isabs(path) else os.path.join(self.build, path))
        # the build directory may lie inside the source tree: test it first
        for name, root in (("build", self.build), ("source", self.source)):
            if p == root or p.startswith(root + os.sep):
                return name, os.path.relpath(p, root)
        return "system", p


# ---------------------------------------------------------------------------------------------
# headers: ninja's deps log

def ninja_program(build):
    cache = os.path.join(build, "CMakeCache.txt")
    if os.path.exists(cache):
        with open(cache, encoding="utf-8", errors="replace") as f:
            for line in f:
                if line.startswith("CMAKE_MAKE_PROGRAM:"):
                    return line.split("=", 1)[1].strip()
    return "ninja"


def read_deps_text(args):
    if args.deps_file:
        with open(args.deps_file, encoding="utf-8", errors="replace") as f:
            return f.read(), args.deps_file
    if not os.path.exists(os.path.join(args.build, "build.ninja")):
        return None, "no build.ninja in %s (not a configured Ninja build)" % args.build
    if not os.path.exists(os.path.join(args.build, ".ninja_deps")):
        return None, "no .ninja_deps in %s (nothing compiled yet)" % args.build
    ninja = ninja_program(args.build)
    try:
        out = subprocess.run([ninja, "-C", args.build, "-t", "deps"], check=True,
                             stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                             universal_newlines=True)
    except (OSError, subprocess.CalledProcessError) as e:
        return None, "`%s -C %s -t deps` failed: %s" % (ninja, args.build, e)
    return out.stdout, "%s -C %s -t deps" % (ninja, args.build)


def parse_deps(text):
    """{object path (relative to the build directory): [header paths]}."""
    deps = {}
    current = None
    head = re.compile(r"^(\S.*?): #deps \d+")
    for line in text.splitlines():
        if not line.strip():
            continue
        if line.startswith((" ", "\t")):
            if current is not None:
                deps[current].append(line.strip())
            continue
        m = head.match(line)
        current = m.group(1) if m else None
        if current is not None:
            deps[current] = []
    return deps


def current_objects(build):
    """The objects the present build.ninja compiles (from compile_commands.json), or None."""
    path = os.path.join(build, "compile_commands.json")
    if not os.path.exists(path):
        return None
    with open(path, encoding="utf-8") as f:
        entries = json.load(f)
    objects = set()
    for e in entries:
        if "output" in e:
            objects.add(os.path.normpath(e["output"]))
            continue
        words = e["arguments"] if "arguments" in e else shlex.split(e["command"])
        if "-o" in words:
            objects.add(os.path.normpath(words[words.index("-o") + 1]))
    return objects


def object_owner(obj):
    """(folder of the target's CMakeLists.txt, target name) from <folder>/CMakeFiles/<t>.dir/..."""
    m = re.match(r"^(?:(.*)/)?CMakeFiles/([^/]+)\.dir/", obj)
    if not m:
        return None, None
    return m.group(1) or ".", m.group(2)


def check_headers(tree, deps, objects, violations):
    checked = {"components": 0, "libs": 0, "exempt": 0, "other": 0}
    headers_seen = 0
    dead = 0
    for obj in sorted(deps):
        if objects is not None and os.path.normpath(obj) not in objects:
            dead += 1  # a record of an object the present build no longer makes
            continue
        folder, target = object_owner(obj)
        if folder is None:
            continue
        kind = kind_of(folder)
        checked[kind] += 1
        if kind not in ("components", "libs"):
            continue
        owner = owner_of(folder)
        # every file read, the source first: a component compiling another's source breaks the
        # rule as an include does
        for header in deps[obj]:
            headers_seen += 1
            root, rel = tree.where(header)
            if root in ("source", "build"):
                hdr_owner = owner_of(rel)
                if hdr_owner and hdr_owner.startswith("components/"):
                    if kind == "libs":
                        violations.append(
                            "header: %s (library %s, target %s) includes %s, a component's header"
                            % (obj, owner, target, rel))
                    elif hdr_owner != owner:
                        violations.append(
                            "header: %s (component %s, target %s) includes %s, %s's header"
                            % (obj, owner, target, rel, hdr_owner))
                if root == "build" and GENERATED_IDL.search("/" + rel) and kind == "libs" \
                        and target not in IDL_TARGETS:
                    violations.append("header: %s (library %s, target %s) includes the generated "
                                      "IDL header %s: of the libraries only %s may"
                                      % (obj, owner, target, rel, ", ".join(sorted(IDL_TARGETS))))
            absolute = os.path.normpath(header if os.path.isabs(header)
                                        else os.path.join(tree.build, header))
            for name, matches, allowed in ENGINE_HEADERS:
                if owner not in allowed and matches(absolute):
                    violations.append("header: %s (%s) includes %s: only %s may include %s"
                                      % (obj, owner, absolute, ", ".join(sorted(allowed)), name))
            if owner in PLAIN_LIBRARIES:
                for name, matches in PLAIN_FORBIDDEN:
                    if matches(absolute):
                        violations.append("header: %s (%s) includes %s: %s knows no %s"
                                          % (obj, owner, absolute, owner, name))
    return checked, headers_seen, dead


# ---------------------------------------------------------------------------------------------
# links: CMake's File API

def read_codemodel(reply_dir):
    """(targets, None) or (None, why): targets = {id: {name, type, folder, deps: [id]}}."""
    indexes = sorted(glob.glob(os.path.join(reply_dir, "index-*.json")))
    if not indexes:
        return None, "no File API reply in %s" % reply_dir
    with open(indexes[-1], encoding="utf-8") as f:
        index = json.load(f)
    codemodel = None
    for obj in index.get("objects", []):
        if obj.get("kind") == "codemodel" and obj.get("version", {}).get("major") == 2:
            codemodel = obj["jsonFile"]
    if codemodel is None:
        return None, "the File API reply %s holds no codemodel-v2" % indexes[-1]
    with open(os.path.join(reply_dir, codemodel), encoding="utf-8") as f:
        model = json.load(f)
    config = model["configurations"][0]
    folders = [d["source"] for d in config["directories"]]
    targets = {}
    for t in config["targets"]:
        with open(os.path.join(reply_dir, t["jsonFile"]), encoding="utf-8") as f:
            detail = json.load(f)
        targets[t["id"]] = {
            "name": t["name"],
            "type": detail.get("type", ""),
            "folder": folders[t["directoryIndex"]],
            "deps": [d["id"] for d in detail.get("dependencies", [])],
        }
    return targets, None


def reply_is_current(reply_dir, build):
    """False when the newest reply predates build.ninja (CMake ran since without the query)."""
    indexes = sorted(glob.glob(os.path.join(reply_dir, "index-*.json")))
    ninja_file = os.path.join(build, "build.ninja")
    if not indexes or not os.path.exists(ninja_file):
        return True
    return os.path.getmtime(indexes[-1]) + 60 >= os.path.getmtime(ninja_file)


def closure(targets, start):
    """{id: the chain of target names from start to it} for everything start depends on."""
    seen = {}
    stack = [(start, [targets[start]["name"]])]
    while stack:
        tid, chain = stack.pop()
        for dep in targets[tid]["deps"]:
            if dep in seen or dep not in targets:
                continue
            seen[dep] = chain + [targets[dep]["name"]]
            stack.append((dep, seen[dep]))
    return seen


def check_links(targets, violations):
    checked = {"components": 0, "libs": 0, "exempt": 0, "other": 0}
    edges = 0
    for tid, t in sorted(targets.items(), key=lambda kv: kv[1]["name"]):
        kind = kind_of(t["folder"])
        checked[kind] += 1
        edges += len(t["deps"])
        if kind not in ("components", "libs"):
            continue
        owner = owner_of(t["folder"])
        for dep, chain in sorted(closure(targets, tid).items(), key=lambda kv: kv[1]):
            dep_owner = owner_of(targets[dep]["folder"])
            if not dep_owner or not dep_owner.startswith("components/"):
                continue
            how = " -> ".join(chain)
            if kind == "libs":
                violations.append("link: %s (library %s) depends on %s, defined in %s (%s)"
                                  % (t["name"], owner, targets[dep]["name"], dep_owner, how))
            elif dep_owner != owner:
                violations.append("link: %s (component %s) depends on %s, defined in %s (%s)"
                                  % (t["name"], owner, targets[dep]["name"], dep_owner, how))
    return checked, edges


# ---------------------------------------------------------------------------------------------

def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0],
                                     epilog="exit status: 0 passed, 1 violations, 77 skipped")
    parser.add_argument("--source", required=True, help="the source tree")
    parser.add_argument("--build", required=True, help="the (Ninja) build tree")
    parser.add_argument("--deps-file", help="read this saved `ninja -t deps` output instead")
    parser.add_argument("--file-api-reply",
                        help="read this File API reply folder instead of BUILD/.cmake/api/v1/reply")
    args = parser.parse_args()
    for given in (args.deps_file, args.file_api_reply):
        if given and not os.path.exists(given):
            parser.error("%s does not exist" % given)
    tree = Tree(args.source, args.build)
    violations = []
    skipped = []

    text, origin = read_deps_text(args)
    if text is None:
        skipped.append("header rules not checked: " + origin)
    else:
        deps = parse_deps(text)
        objects = None if args.deps_file else current_objects(tree.build)
        checked, headers, dead = check_headers(tree, deps, objects, violations)
        if not deps:
            skipped.append("header rules not checked: %s lists no object (nothing compiled yet)"
                           % origin)
        else:
            print("headers (%s): %d objects of components, %d of libraries checked, %d header "
                  "reads; %d objects of tests/bench/fuzz and %d others exempt; %d records of "
                  "objects no longer built ignored"
                  % (origin, checked["components"], checked["libs"], headers, checked["exempt"],
                     checked["other"], dead))
            if objects is not None:
                recorded = {os.path.normpath(d) for d in deps}
                missing = sorted(o for o in objects if o not in recorded
                                 and kind_of(object_owner(o)[0] or "") in ("components", "libs"))
                if missing:
                    print("  note: %d objects of components and libraries not compiled yet, "
                          "unchecked (first: %s)" % (len(missing), missing[0]))

    reply = args.file_api_reply or os.path.join(tree.build, ".cmake", "api", "v1", "reply")
    targets, why = read_codemodel(reply)
    if targets is None:
        skipped.append("link rules not checked: %s; CMake answers the query that "
                       "tests/layout/CMakeLists.txt writes at its next configure (`cmake %s`)"
                       % (why, args.build))
    elif not args.file_api_reply and not reply_is_current(reply, tree.build):
        skipped.append("link rules not checked: the File API reply in %s predates build.ninja; "
                       "re-run `cmake %s`" % (reply, args.build))
    else:
        checked, edges = check_links(targets, violations)
        print("links (File API codemodel-v2, %s): %d targets of components, %d of libraries "
              "checked with everything they depend on; %d of tests/bench/fuzz and %d others "
              "exempt; %d direct dependencies"
              % (reply, checked["components"], checked["libs"], checked["exempt"],
                 checked["other"], edges))

    for v in violations:
        print("VIOLATION " + v)
    if violations:
        print("FAILED: %d violations of the layout's rules (docs/architecture.md, \"Rules the "
              "layout keeps\")"
              % len(violations))
        for s in skipped:
            print("  also " + s)
        return 1
    if skipped:
        print("skipped: " + "; ".join(skipped))
        return SKIP
    print("passed: components are leaves, libraries see no component, engines stay in their "
          "adapters")
    return 0


if __name__ == "__main__":
    sys.exit(main())
