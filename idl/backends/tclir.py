# -*- python -*-
"""omniidl back-end: type information for Tcl Combat.

Tcl Combat finds the signatures of operations in a type repository that it fills either from an
Interface Repository (which omniORB does not have) or with `combat::ir add {...}`. This back-end
writes that `combat::ir add` data, in the format Combat's SimpleTypeRepository reads (the format
idl2tcl writes), straight from the IDL:

    omniidl -p idl/backends -btclir -Wbo=build/idl/caliper/caliper_ir.tcl -Iidl a.idl b.idl ...

Options (-Wb...):
    o=FILE   where to write (default: <stem of the first IDL file>_ir.tcl in the working dir)

Several IDL files may be given: omniidl calls run() once per file, and the back-end writes one
file holding every declaration of all of them, included files first, each declaration once.
Types are referred to by repository id, so the order matters: a declaration comes after what it
uses (forward declarations of interfaces and structs are written as such).

Item formats (each a Tcl list; HDR is {REPOID NAME VERSION}):
    {module HDR {ITEM ...}}
    {interface HDR {BASE-REPOID ...} {ITEM ...}}      forward: {interface HDR}
    {struct HDR {{NAME TYPE} ...} {NESTED-ITEM ...}}  forward: {struct HDR}
    {exception HDR {{NAME TYPE} ...} {NESTED-ITEM ...}}
    {union HDR DISCRIMINATOR-TYPE {{LABEL NAME TYPE} ...} {NESTED-ITEM ...}}
    {enum HDR {ENUMERATOR ...}}
    {typedef HDR TYPE}
    {const HDR TYPE VALUE}
    {attribute HDR TYPE ?readonly?}
    {operation HDR RESULT-TYPE {{in|out|inout NAME TYPE} ...} {EXCEPTION-REPOID ...} ?oneway?}
    {native HDR}
TYPE is a base type name (long, {unsigned long long}, string, ...), Object, {string BOUND},
{sequence TYPE ?BOUND?}, {array TYPE LENGTH}, {fixed DIGITS SCALE} or a repository id.
"""

import os
import sys

from omniidl import idlast, idltype, idlvisitor

_BASE_NAMES = {
    idltype.tk_void: "void",
    idltype.tk_short: "short",
    idltype.tk_long: "long",
    idltype.tk_ushort: "unsigned short",
    idltype.tk_ulong: "unsigned long",
    idltype.tk_float: "float",
    idltype.tk_double: "double",
    idltype.tk_boolean: "boolean",
    idltype.tk_char: "char",
    idltype.tk_octet: "octet",
    idltype.tk_any: "any",
    idltype.tk_TypeCode: "TypeCode",
    idltype.tk_longlong: "long long",
    idltype.tk_ulonglong: "unsigned long long",
    idltype.tk_longdouble: "long double",
    idltype.tk_wchar: "wchar",
}

_DIRECTIONS = {0: "in", 1: "out", 2: "inout"}


class BackendError(Exception):
    pass


# ---------------------------------------------------------------------------------------------
# Tcl list syntax


class Nested(list):
    """A list written over several lines, one element per line (module and interface bodies)."""


_SPECIAL = set(' \t\n\r\f\v{}[]$"\\;#')


def tcl_word(value):
    """One element of a Tcl list, quoted so that the list parser gives back `value`."""
    if value == "":
        return "{}"
    if not any(c in _SPECIAL for c in value):
        return value
    if _braces_ok(value):
        return "{" + value + "}"
    out = []
    for c in value:
        if c in _SPECIAL:
            out.append({"\n": "\\n", "\t": "\\t", "\r": "\\r", "\f": "\\f",
                        "\v": "\\v"}.get(c, "\\" + c))
        else:
            out.append(c)
    return "".join(out)


def _braces_ok(value):
    """True when `value` can be written between braces verbatim."""
    if value.endswith("\\"):
        return False
    depth = 0
    escaped = False
    for c in value:
        if escaped:
            escaped = False
        elif c == "\\":
            escaped = True
        elif c == "{":
            depth += 1
        elif c == "}":
            depth -= 1
            if depth < 0:
                return False
    return depth == 0


def to_tcl(value, indent=0):
    """A (nested) Python list as Tcl list text; Nested lists span lines."""
    if isinstance(value, str):
        return tcl_word(value)
    if isinstance(value, Nested):
        if not value:
            return "{}"
        pad = "  " * (indent + 1)
        lines = [pad + to_tcl(v, indent + 1) for v in value]
        return "{\n" + "\n".join(lines) + "\n" + "  " * indent + "}"
    return "{" + " ".join(to_tcl(v, indent) for v in value) + "}"


# ---------------------------------------------------------------------------------------------
# Types


def header(decl):
    repo_id = decl.repoId()
    version = "1.0"
    if repo_id.startswith("IDL:") and repo_id.count(":") >= 2:
        version = repo_id.rsplit(":", 1)[1]
    return [repo_id, decl.identifier(), version]


class TypeName(idlvisitor.TypeVisitor):
    """How an IDL type is named in Combat's repository data (a string or a nested list)."""

    def __init__(self):
        self.result = None

    def visitBaseType(self, t):
        if t.kind() not in _BASE_NAMES:
            raise BackendError("type kind %d is not supported by Tcl Combat" % t.kind())
        self.result = _BASE_NAMES[t.kind()]

    def visitStringType(self, t):
        self.result = ["string", str(t.bound())] if t.bound() else "string"

    def visitWStringType(self, t):
        self.result = ["wstring", str(t.bound())] if t.bound() else "wstring"

    def visitSequenceType(self, t):
        element = type_name(t.seqType())
        self.result = ["sequence", element, str(t.bound())] if t.bound() else \
            ["sequence", element]

    def visitFixedType(self, t):
        self.result = ["fixed", str(t.digits()), str(t.scale())]

    def visitDeclaredType(self, t):
        decl = t.decl()
        if t.scopedName() == ["CORBA", "Object"]:
            self.result = "Object"
        elif t.scopedName() == ["CORBA", "ValueBase"]:
            self.result = "value base"
        elif decl is None:
            raise BackendError("unresolved type " + "::".join(t.scopedName()))
        else:
            self.result = decl.repoId()


def type_name(t):
    visitor = TypeName()
    t.accept(visitor)
    return visitor.result


def declarator_type(base, declarator):
    """The type of one declarator: `base`, or arrays of it for `x[2][3]`."""
    result = base
    for size in reversed(declarator.sizes() or []):
        result = ["array", result, str(size)]
    return result


# ---------------------------------------------------------------------------------------------
# Declarations


class Collector(idlvisitor.AstVisitor):
    """Turns declarations into repository items, skipping what was written before."""

    def __init__(self, done):
        self.done = done      # repository id -> "forward" or "full"
        self.items = None     # where visited declarations go

    def collect(self, decls):
        saved = self.items
        self.items = Nested()
        for d in decls:
            d.accept(self)
        result, self.items = self.items, saved
        return result

    def _new(self, decl, kind="full"):
        """Marks `decl` written; False if it (or more than a forward of it) already was."""
        seen = self.done.get(decl.repoId())
        if seen == "full" or (seen == "forward" and kind == "forward"):
            return False
        self.done[decl.repoId()] = kind
        return True

    # modules and interfaces

    def visitAST(self, node):
        self.items = self.collect(node.declarations())

    def visitModule(self, node):
        body = self.collect(node.definitions())
        if body:
            self.items.append(["module", header(node), body])

    def visitInterface(self, node):
        if node.local():
            return  # Combat ignores local interfaces; they never travel
        if not self._new(node):
            return
        kind = "abstractinterface" if node.abstract() else "interface"
        bases = [b.repoId() for b in node.inherits()]
        body = self.collect(node.contents())
        self.items.append([kind, header(node), bases, body])

    def visitForward(self, node):
        if node.local():
            return
        if not self._new(node, "forward"):
            return
        kind = "abstractinterface" if node.abstract() else "interface"
        self.items.append([kind, header(node)])

    # constructed types

    def _members(self, members):
        """(member list, nested definitions) of a struct or an exception."""
        fields, nested = [], []
        for m in members:
            if m.constrType():
                nested.extend(self.collect([m.memberType().decl()]))
            base = type_name(m.memberType())
            for d in m.declarators():
                fields.append([d.identifier(), declarator_type(base, d)])
        return fields, nested

    def visitStruct(self, node):
        if not self._new(node):
            return
        fields, nested = self._members(node.members())
        self.items.append(["struct", header(node), fields, nested])

    def visitStructForward(self, node):
        if self._new(node, "forward"):
            self.items.append(["struct", header(node)])

    def visitException(self, node):
        if not self._new(node):
            return
        fields, nested = self._members(node.members())
        self.items.append(["exception", header(node), fields, nested])

    def visitUnion(self, node):
        if not self._new(node):
            return
        nested = []
        if node.constrType():
            nested.extend(self.collect([node.switchType().decl()]))
        cases = []
        for case in node.cases():
            if case.constrType():
                nested.extend(self.collect([case.caseType().decl()]))
            ctype = declarator_type(type_name(case.caseType()), case.declarator())
            for label in case.labels():
                cases.append([self._label(label), case.declarator().identifier(), ctype])
        self.items.append(["union", header(node), type_name(node.switchType()), cases, nested])

    def visitUnionForward(self, node):
        if self._new(node, "forward"):
            self.items.append(["union", header(node)])

    @staticmethod
    def _label(label):
        if label.default():
            return "(default)"
        value = label.value()
        if isinstance(value, idlast.Enumerator):
            return value.identifier()
        if label.labelKind() == idltype.tk_boolean:
            return "1" if value else "0"
        if label.labelKind() in (idltype.tk_char, idltype.tk_wchar):
            return value if isinstance(value, str) else chr(value)
        return str(value)

    def visitEnum(self, node):
        if self._new(node):
            self.items.append(["enum", header(node),
                               [e.identifier() for e in node.enumerators()]])

    def visitTypedef(self, node):
        if node.constrType():
            node.aliasType().decl().accept(self)
        base = type_name(node.aliasType())
        for d in node.declarators():
            if self._new(d):
                self.items.append(["typedef", header(d), declarator_type(base, d)])

    def visitConst(self, node):
        if not self._new(node):
            return
        value = node.value()
        kind = node.constKind()
        if isinstance(value, idlast.Enumerator):
            text = value.identifier()
        elif kind == idltype.tk_boolean:
            text = "1" if value else "0"
        elif kind in (idltype.tk_float, idltype.tk_double, idltype.tk_longdouble):
            text = repr(float(value))
        else:
            text = str(value)
        self.items.append(["const", header(node), type_name(node.constType()), text])

    def visitNative(self, node):
        if self._new(node):
            self.items.append(["native", header(node)])

    # interface contents

    def visitAttribute(self, node):
        atype = type_name(node.attrType())
        for d in node.declarators():
            if not self._new(d):
                continue
            item = ["attribute", header(d), atype]
            if node.readonly():
                item.append("readonly")
            self.items.append(item)

    def visitOperation(self, node):
        if not self._new(node):
            return
        params = [[_DIRECTIONS[p.direction()], p.identifier(), type_name(p.paramType())]
                  for p in node.parameters()]
        item = ["operation", header(node), type_name(node.returnType()), params,
                [e.repoId() for e in node.raises()]]
        if node.oneway():
            item.append("oneway")
        self.items.append(item)

    # value types have no use in Caliper's IDL; refuse them instead of writing half of them

    def _unsupported(self, node):
        raise BackendError("%s:%d: value types are not supported by the tclir back-end"
                           % (node.file(), node.line()))

    visitValue = visitValueAbs = visitValueBox = visitValueForward = _unsupported


# ---------------------------------------------------------------------------------------------
# Entry point

_state = {"done": {}, "items": [], "sources": [], "output": None}


def _merge(into, items):
    """Appends `items`, merging a module into the last top-level module of the same id."""
    for item in items:
        if item[0] == "module" and into and into[-1][0] == "module" and \
                into[-1][1][0] == item[1][0]:
            _merge(into[-1][2], item[2])
        else:
            into.append(item)


def _write(path):
    lines = [
        "# Type information for Tcl Combat (combat::ir add), generated by the tclir omniidl",
        "# back-end (idl/backends/tclir.py) from:",
    ]
    lines += ["#   " + s for s in _state["sources"]]
    lines += ["# Do not edit; the build writes it again.", "", "package require combat", ""]
    text = "\n".join(lines) + "\n"
    for item in _state["items"]:
        text += "combat::ir add " + to_tcl(Nested([item])) + "\n\n"
    directory = os.path.dirname(os.path.abspath(path))
    os.makedirs(directory, exist_ok=True)
    tmp = path + ".tmp"
    with open(tmp, "w") as f:
        f.write(text)
    os.replace(tmp, path)


def run(tree, args):
    output = None
    for arg in args:
        if arg.startswith("o="):
            output = arg[2:]
        else:
            sys.stderr.write("omniidl: tclir: unknown option -Wb%s\n" % arg)
            sys.exit(1)
    if output is None:
        output = _state["output"] or \
            os.path.splitext(os.path.basename(tree.file()))[0] + "_ir.tcl"
    _state["output"] = output

    collector = Collector(_state["done"])
    try:
        tree.accept(collector)
    except BackendError as e:
        sys.stderr.write("omniidl: tclir: %s\n" % e)
        sys.exit(1)
    _merge(_state["items"], collector.items)
    _state["sources"].append(os.path.basename(tree.file()))
    _write(output)
