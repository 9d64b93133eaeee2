#!/usr/bin/env python3
"""Type support for Fast DDS 2.10 to 2.14 (Fast CDR 2) from rsg's IDL, where fastddsgen 3 is missing.

    tools/fastdds2_typesupport.py [--typeobject] IDL OUTDIR

Writes, with fastddsgen 2's file names and class interface (so rsg's sources include and call the
same on every Fast DDS): <name>.h (the structs, their accessors, the IDL's constants), <name>.cxx
(Fast CDR 2 serialization, XCDR1 or XCDR2 as the payload asks), <name>PubSubTypes.h/.cxx (the
TopicDataType) and, with --typeobject, <name>TypeObject.h/.cxx (register<name>Types(): the XTypes
1.1 TypeObjects that Fast DDS 2's DDS-SQL filter factory looks the members up in).

Why not fastddsgen: fastddsgen 2.3 (Debian 12) writes for Fast CDR 1 (`#error Generated ... is not
compatible`, `DDS_CDR`), fastddsgen 4 for Fast DDS 3, and the fastddsgen 3 that 2.10-2.14 need is
neither in Debian nor on Maven Central (docs/fastdds-versions.md).

The wire is fastddsgen's: every struct is final (plain CDR, no DHEADER), members in IDL order, no
keys. The TypeObjects are built member by member as fastddsgen 2.3 builds them (flags, member ids,
names, unqualified type names, MD5 equivalence hashes of the little-endian XCDR1 serialization), so
that a 2.9 and a 2.14 endpoint announcing TypeInformation for the same type carry the same type
identifiers and match. The largest serialized size follows fastddsgen 2.3's rule too (an unbounded
string counts 255 characters, an unbounded sequence 100 elements), so a writer's preallocated
history holds what it held on 2.9.

The IDL subset is the one rsg writes: modules, `const`, `struct` of primitives, strings (bounded or
not), one-dimensional arrays, unbounded sequences and other structs. Anything else stops with an
error naming it, never a silent guess. Standard library only.
"""
import argparse
import re
import sys
from dataclasses import dataclass, field
from pathlib import Path

# IDL primitive -> (C++ type, CDR size, TypeObjectFactory name)
PRIMITIVES = {
    "octet": ("uint8_t", 1, "uint8_t"),
    "boolean": ("bool", 1, "bool"),
    "char": ("char", 1, "char"),
    "short": ("int16_t", 2, "int16_t"),
    "unsigned short": ("uint16_t", 2, "uint16_t"),
    "long": ("int32_t", 4, "int32_t"),
    "unsigned long": ("uint32_t", 4, "uint32_t"),
    "long long": ("int64_t", 8, "int64_t"),
    "unsigned long long": ("uint64_t", 8, "uint64_t"),
    "float": ("float", 4, "float"),
    "double": ("double", 8, "double"),
}
UNBOUNDED_STRING = 255  # fastddsgen 2.3's assumption for the largest size
UNBOUNDED_SEQUENCE = 100


class IdlError(Exception):
    pass


@dataclass
class Type:
    kind: str  # primitive, string, sequence, struct
    name: str = ""  # primitive IDL name, or the struct's scoped name (a::b::C)
    bound: int = 0  # string<N>
    element: "Type | None" = None  # sequence<element>


@dataclass
class Member:
    name: str
    type: Type
    array: int = 0  # 0: not an array


@dataclass
class Struct:
    scope: list
    name: str
    members: list = field(default_factory=list)

    @property
    def scoped(self):
        return "::".join(self.scope + [self.name])


@dataclass
class Const:
    scope: list
    type: str
    name: str
    value: str


def tokenize(text):
    text = re.sub(r"//[^\n]*", " ", text)
    text = re.sub(r"/\*.*?\*/", " ", text, flags=re.S)
    return re.findall(r"::|[A-Za-z_][A-Za-z_0-9]*|-?\d+(?:\.\d*)?|[{}<>;\[\]=,]|\S", text)


class Parser:
    def __init__(self, text):
        self.tokens = tokenize(text)
        self.at = 0
        self.structs = []
        self.consts = []

    def peek(self, ahead=0):
        return self.tokens[self.at + ahead] if self.at + ahead < len(self.tokens) else None

    def take(self, expected=None):
        token = self.peek()
        if token is None or (expected is not None and token != expected):
            raise IdlError(f"expected {expected or 'a token'}, found {token!r} (token {self.at})")
        self.at += 1
        return token

    def parse(self):
        self.definitions([])
        return self.structs, self.consts

    def definitions(self, scope):
        while self.peek() not in (None, "}"):
            keyword = self.take()
            if keyword == "module":
                name = self.take()
                self.take("{")
                self.definitions(scope + [name])
                self.take("}")
                self.take(";")
            elif keyword == "struct":
                self.struct(scope)
            elif keyword == "const":
                kind = self.type_name()
                name = self.take()
                self.take("=")
                value = self.take()
                self.take(";")
                self.consts.append(Const(scope, kind, name, value))
            else:
                raise IdlError(f"unsupported IDL construct {keyword!r} (rsg's subset: module, const, struct)")

    def type_name(self):
        token = self.take()
        if token == "unsigned":
            token += " " + self.take()
        if token in ("long", "unsigned long") and self.peek() == "long":
            token += " " + self.take()
        return token

    def type(self, scope):
        token = self.peek()
        if token == "string":
            self.take()
            bound = 0
            if self.peek() == "<":
                self.take()
                bound = int(self.take())
                self.take(">")
            return Type("string", bound=bound)
        if token == "sequence":
            self.take()
            self.take("<")
            element = self.type(scope)
            if self.peek() == ",":
                raise IdlError("bounded sequences are outside rsg's subset")
            self.take(">")
            return Type("sequence", element=element)
        if token in ("wstring", "map", "any", "union", "enum", "bitmask", "bitset", "fixed"):
            raise IdlError(f"{token} is outside rsg's subset")
        name = self.type_name()
        if name in PRIMITIVES:
            return Type("primitive", name)
        while self.peek() == "::":
            name += self.take() + self.take()
        return Type("struct", self.resolve(name, scope))

    def resolve(self, name, scope):
        names = {s.scoped: s for s in self.structs}
        if name.startswith("::"):
            name = name[2:]
        for depth in range(len(scope), -1, -1):
            candidate = "::".join(scope[:depth] + [name])
            if candidate in names:
                return candidate
        raise IdlError(f"unknown type {name!r} in {'::'.join(scope) or 'global scope'}")

    def struct(self, scope):
        struct = Struct(scope, self.take())
        self.take("{")
        while self.peek() != "}":
            if self.peek() == "@":
                raise IdlError("annotations are outside rsg's subset (every struct is final)")
            kind = self.type(scope)
            while True:
                member = Member(self.take(), kind)
                if self.peek() == "[":
                    self.take()
                    member.array = int(self.take())
                    self.take("]")
                    if self.peek() == "[":
                        raise IdlError(f"{member.name}: multi-dimensional arrays are outside rsg's subset")
                struct.members.append(member)
                if self.peek() != ",":
                    break
                self.take(",")
            self.take(";")
        self.take("}")
        self.take(";")
        self.structs.append(struct)


def cpp_type(kind):
    if kind.kind == "primitive":
        return PRIMITIVES[kind.name][0]
    if kind.kind == "string":
        return f"eprosima::fastcdr::fixed_string<{kind.bound}>" if kind.bound else "std::string"
    if kind.kind == "sequence":
        return f"std::vector<{cpp_type(kind.element)}>"
    return "::" + kind.name


def member_cpp_type(member):
    base = cpp_type(member.type)
    return f"std::array<{base}, {member.array}>" if member.array else base


def align(offset, size):
    return (size - offset % size) & (size - 1)


class Sizes:
    """fastddsgen 2.3's getMaxCdrSerializedSize(), XCDR1, from alignment 0."""

    def __init__(self, structs):
        self.structs = {s.scoped: s for s in structs}

    def of_type(self, kind, at):
        if kind.kind == "primitive":
            size = PRIMITIVES[kind.name][1]
            return size + align(at, size)
        if kind.kind == "string":
            return 4 + align(at, 4) + (kind.bound or UNBOUNDED_STRING) + 1
        if kind.kind == "sequence":
            start = at
            at += 4 + align(at, 4)
            element = kind.element
            if element.kind == "primitive":
                size = PRIMITIVES[element.name][1]
                at += UNBOUNDED_SEQUENCE * size + align(at, size)
            else:
                for _ in range(UNBOUNDED_SEQUENCE):
                    at += self.of_type(element, at)
            return at - start
        return self.of_struct(self.structs[kind.name], at)

    def of_member(self, member, at):
        if not member.array:
            return self.of_type(member.type, at)
        if member.type.kind == "primitive":
            size = PRIMITIVES[member.type.name][1]
            return member.array * size + align(at, size)
        start = at
        for _ in range(member.array):
            at += self.of_type(member.type, at)
        return at - start

    def of_struct(self, struct, at=0):
        start = at
        for member in struct.members:
            at += self.of_member(member, at)
        return at - start

    def bounded(self, kind_or_struct):
        if isinstance(kind_or_struct, Struct):
            return all(self.bounded(m.type) for m in kind_or_struct.members)
        if kind_or_struct.kind == "string":
            return kind_or_struct.bound > 0
        if kind_or_struct.kind == "sequence":
            return False
        if kind_or_struct.kind == "struct":
            return self.bounded(self.structs[kind_or_struct.name])
        return True

    def plain(self, struct):
        """Whether the C++ object is its XCDR1 bytes: primitives and arrays of them only (C++ and XCDR1
        align each at its size), and no tail padding (checked by a static_assert in <name>.cxx)."""
        return all(m.type.kind == "primitive" for m in struct.members)


HEADER = """// Generated by tools/fastdds2_typesupport.py from {idl}: do not edit.
"""


def namespace_open(scope):
    return "".join(f"namespace {name} {{\n" for name in scope)


def namespace_close(scope):
    return "".join(f"}}  // namespace {name}\n" for name in reversed(scope))


def gen_types_header(name, idl, structs, consts):
    out = [HEADER.format(idl=idl), f"#ifndef RSG_GENERATED_{name.upper()}_H\n#define RSG_GENERATED_{name.upper()}_H\n\n"]
    out.append("#include <array>\n#include <cstddef>\n#include <cstdint>\n#include <string>\n#include <utility>\n"
               "#include <vector>\n\n#include <fastcdr/Cdr.h>\n#include <fastcdr/CdrSizeCalculator.hpp>\n"
               "#include <fastcdr/cdr/fixed_size_string.hpp>\n\n")
    scope = None
    items = [(c.scope, c) for c in consts] + [(s.scope, s) for s in structs]
    # Constants first within each module, as the IDL declares them before the structs that use them.
    for item_scope, item in items:
        if item_scope != scope:
            if scope is not None:
                out.append(namespace_close(scope) + "\n")
            out.append(namespace_open(item_scope))
            scope = item_scope
        if isinstance(item, Const):
            out.append(f"const {PRIMITIVES[item.type][0]} {item.name} = {item.value};\n")
            continue
        out.append(f"\nclass {item.name} {{\n public:\n")
        out.append(f"  {item.name}() = default;\n")
        out.append(f"  bool operator==(const {item.name}& other) const {{\n    return ")
        out.append(" &&\n           ".join(f"m_{m.name} == other.m_{m.name}" for m in item.members) or "true")
        out.append(";\n  }\n")
        out.append(f"  bool operator!=(const {item.name}& other) const {{ return !(*this == other); }}\n\n")
        for member in item.members:
            kind = member_cpp_type(member)
            n = member.name
            if member.type.kind == "primitive" and not member.array:
                out.append(f"  void {n}({kind} value) {{ m_{n} = value; }}\n")
                out.append(f"  {kind} {n}() const {{ return m_{n}; }}\n")
            else:
                out.append(f"  void {n}(const {kind}& value) {{ m_{n} = value; }}\n")
                out.append(f"  void {n}({kind}&& value) {{ m_{n} = std::move(value); }}\n")
                out.append(f"  const {kind}& {n}() const {{ return m_{n}; }}\n")
            out.append(f"  {kind}& {n}() {{ return m_{n}; }}\n")
        out.append("\n  /// fastddsgen 2's interface: the largest XCDR1 size of a sample.\n")
        out.append("  static size_t getMaxCdrSerializedSize();\n")
        out.append("  static bool isKeyDefined() { return false; }\n\n private:\n")
        for member in item.members:
            initial = "{}" if member.type.kind != "primitive" or member.array else \
                ("{false}" if member.type.name == "boolean" else "{0}")
            out.append(f"  {member_cpp_type(member)} m_{member.name}{initial};\n")
        out.append("};\n")
    if scope is not None:
        out.append(namespace_close(scope))
    out.append("\nnamespace eprosima {\nnamespace fastcdr {\n")
    for s in structs:
        t = "::" + s.scoped
        out.append(f"template <>\nsize_t calculate_serialized_size(CdrSizeCalculator& calculator, const {t}& data,\n"
                   f"                                 size_t& current_alignment);\n")
        out.append(f"template <>\nvoid serialize(Cdr& cdr, const {t}& data);\n")
        out.append(f"template <>\nvoid deserialize(Cdr& cdr, {t}& data);\n")
    out.append("}  // namespace fastcdr\n}  // namespace eprosima\n\n#endif\n")
    return "".join(out)


def gen_types_source(name, idl, structs, sizes):
    out = [HEADER.format(idl=idl), f'#include "{name}.h"\n\n#include <fastcdr/Cdr.h>\n#include <fastcdr/CdrSizeCalculator.hpp>\n\n']
    for s in structs:
        t = "::" + s.scoped
        out.append(f"size_t {s.scoped}::getMaxCdrSerializedSize() {{ return {sizes.of_struct(s)}u; }}\n\n")
        if sizes.plain(s):
            out.append(f"static_assert(sizeof({t}) == {sizes.of_struct(s)}u, \"a plain type's object is its XCDR1 bytes\");\n\n")
    out.append("namespace eprosima {\nnamespace fastcdr {\n\n")
    encoding = ("CdrVersion::XCDRv2 == {c}.get_cdr_version() ? EncodingAlgorithmFlag::PLAIN_CDR2 "
                ": EncodingAlgorithmFlag::PLAIN_CDR")
    for s in structs:
        t = "::" + s.scoped
        out.append(f"template <>\nsize_t calculate_serialized_size(CdrSizeCalculator& calculator, const {t}& data,\n"
                   f"                                 size_t& current_alignment) {{\n")
        out.append("  const EncodingAlgorithmFlag previous = calculator.get_encoding();\n")
        out.append(f"  size_t size = calculator.begin_calculate_type_serialized_size({encoding.format(c='calculator')}, current_alignment);\n")
        for index, member in enumerate(s.members):
            out.append(f"  size += calculator.calculate_member_serialized_size(MemberId({index}), data.{member.name}(), current_alignment);\n")
        out.append("  size += calculator.end_calculate_type_serialized_size(previous, current_alignment);\n")
        out.append("  return size;\n}\n\n")
        out.append(f"template <>\nvoid serialize(Cdr& cdr, const {t}& data) {{\n")
        out.append("  Cdr::state state(cdr);\n")
        out.append(f"  cdr.begin_serialize_type(state, {encoding.format(c='cdr')});\n")
        if s.members:
            out.append("  cdr")
            for index, member in enumerate(s.members):
                out.append(f"\n      << MemberId({index}) << data.{member.name}()")
            out.append(";\n")
        out.append("  cdr.end_serialize_type(state);\n}\n\n")
        out.append(f"template <>\nvoid deserialize(Cdr& cdr, {t}& data) {{\n")
        out.append(f"  cdr.deserialize_type({encoding.format(c='cdr')}, [&data](Cdr& in, const MemberId& id) -> bool {{\n")
        out.append("    switch (id.id) {\n")
        for index, member in enumerate(s.members):
            out.append(f"      case {index}:\n        in >> data.{member.name}();\n        return true;\n")
        out.append("      default:\n        return false;\n    }\n  });\n}\n\n")
    out.append("}  // namespace fastcdr\n}  // namespace eprosima\n")
    return "".join(out)


def gen_pubsub_header(name, idl, structs, sizes):
    guard = f"RSG_GENERATED_{name.upper()}_PUBSUBTYPES_H"
    out = [HEADER.format(idl=idl), f"#ifndef {guard}\n#define {guard}\n\n"]
    out.append("#include <fastdds/dds/topic/TopicDataType.hpp>\n\n")
    out.append(f'#include "{name}.h"\n\n')
    for s in structs:
        out.append(namespace_open(s.scope))
        plain = "true" if sizes.plain(s) else "false"
        out.append(f"""
/// The TopicDataType of {s.scoped}: final, unkeyed, XCDR1 unless the writer asks for XCDR2.
class {s.name}PubSubType : public eprosima::fastdds::dds::TopicDataType {{
 public:
  typedef {s.name} type;

  {s.name}PubSubType();
  ~{s.name}PubSubType() override = default;

  bool serialize(void* data, eprosima::fastrtps::rtps::SerializedPayload_t* payload) override;
  bool serialize(void* data, eprosima::fastrtps::rtps::SerializedPayload_t* payload,
                 eprosima::fastdds::dds::DataRepresentationId_t representation) override;
  bool deserialize(eprosima::fastrtps::rtps::SerializedPayload_t* payload, void* data) override;
  std::function<uint32_t()> getSerializedSizeProvider(void* data) override;
  std::function<uint32_t()> getSerializedSizeProvider(
      void* data, eprosima::fastdds::dds::DataRepresentationId_t representation) override;
  bool getKey(void* data, eprosima::fastrtps::rtps::InstanceHandle_t* handle, bool force_md5 = false) override;
  void* createData() override;
  void deleteData(void* data) override;
  bool is_bounded() const override {{ return {"true" if sizes.bounded(s) else "false"}; }}
  bool is_plain() const override {{ return {plain}; }}
  /// Plain in XCDR1 only: XCDR2 aligns 8-byte members at 4, unlike the C++ object.
  bool is_plain(eprosima::fastdds::dds::DataRepresentationId_t representation) const override {{
    return {plain} && representation == eprosima::fastdds::dds::XCDR_DATA_REPRESENTATION;
  }}
  bool construct_sample(void* memory) const override {{
    new (memory) {s.name}();
    return true;
  }}
}};
""")
        out.append(namespace_close(s.scope))
    out.append("\n#endif\n")
    return "".join(out)


def gen_pubsub_source(name, idl, structs):
    out = [HEADER.format(idl=idl), f'#include "{name}PubSubTypes.h"\n\n#include <fastcdr/Cdr.h>\n'
           "#include <fastcdr/CdrSizeCalculator.hpp>\n#include <fastcdr/FastBuffer.h>\n"
           "#include <fastcdr/exceptions/Exception.h>\n\n"]
    out.append("""namespace {

using eprosima::fastdds::dds::DataRepresentationId_t;
using eprosima::fastrtps::rtps::SerializedPayload_t;

eprosima::fastcdr::CdrVersion cdr_version(DataRepresentationId_t representation) {
  return representation == eprosima::fastdds::dds::XCDR_DATA_REPRESENTATION ? eprosima::fastcdr::CdrVersion::XCDRv1
                                                                             : eprosima::fastcdr::CdrVersion::XCDRv2;
}

template <class T>
bool serialize_sample(const T& sample, SerializedPayload_t* payload, DataRepresentationId_t representation) {
  eprosima::fastcdr::FastBuffer buffer(reinterpret_cast<char*>(payload->data), payload->max_size);
  eprosima::fastcdr::Cdr cdr(buffer, eprosima::fastcdr::Cdr::DEFAULT_ENDIAN, cdr_version(representation));
  payload->encapsulation = cdr.endianness() == eprosima::fastcdr::Cdr::BIG_ENDIANNESS ? CDR_BE : CDR_LE;
  cdr.set_encoding_flag(representation == eprosima::fastdds::dds::XCDR_DATA_REPRESENTATION
                            ? eprosima::fastcdr::EncodingAlgorithmFlag::PLAIN_CDR
                            : eprosima::fastcdr::EncodingAlgorithmFlag::PLAIN_CDR2);
  try {
    cdr.serialize_encapsulation();
    cdr << sample;
  } catch (const eprosima::fastcdr::exception::Exception&) {
    return false;
  }
  payload->length = static_cast<uint32_t>(cdr.get_serialized_data_length());
  return true;
}

template <class T>
bool deserialize_sample(SerializedPayload_t* payload, T& sample) {
  try {
    eprosima::fastcdr::FastBuffer buffer(reinterpret_cast<char*>(payload->data), payload->length);
    eprosima::fastcdr::Cdr cdr(buffer, eprosima::fastcdr::Cdr::DEFAULT_ENDIAN);
    cdr.read_encapsulation();
    payload->encapsulation = cdr.endianness() == eprosima::fastcdr::Cdr::BIG_ENDIANNESS ? CDR_BE : CDR_LE;
    cdr >> sample;
  } catch (const eprosima::fastcdr::exception::Exception&) {
    return false;
  }
  return true;
}

template <class T>
std::function<uint32_t()> size_provider(void* data, DataRepresentationId_t representation) {
  return [data, representation]() -> uint32_t {
    eprosima::fastcdr::CdrSizeCalculator calculator(cdr_version(representation));
    size_t alignment = 0;
    return static_cast<uint32_t>(calculator.calculate_serialized_size(*static_cast<T*>(data), alignment)) +
           4u;  // encapsulation
  };
}

}  // namespace

""")
    for s in structs:
        t = "::" + s.scoped
        p = f"{s.scoped}PubSubType"
        out.append(f"""{p}::{s.name}PubSubType() {{
  setName("{s.scoped}");
  size_t size = {t}::getMaxCdrSerializedSize();
  size += (4 - size % 4) % 4;  // possible submessage alignment, as fastddsgen 2.3 counts it
  m_typeSize = static_cast<uint32_t>(size) + 4;  // encapsulation
  m_isGetKeyDefined = false;
}}

bool {p}::serialize(void* data, SerializedPayload_t* payload) {{
  return serialize(data, payload, eprosima::fastdds::dds::XCDR_DATA_REPRESENTATION);
}}

bool {p}::serialize(void* data, SerializedPayload_t* payload, DataRepresentationId_t representation) {{
  return serialize_sample(*static_cast<{t}*>(data), payload, representation);
}}

bool {p}::deserialize(SerializedPayload_t* payload, void* data) {{
  return deserialize_sample(payload, *static_cast<{t}*>(data));
}}

std::function<uint32_t()> {p}::getSerializedSizeProvider(void* data) {{
  return size_provider<{t}>(data, eprosima::fastdds::dds::XCDR_DATA_REPRESENTATION);
}}

std::function<uint32_t()> {p}::getSerializedSizeProvider(void* data, DataRepresentationId_t representation) {{
  return size_provider<{t}>(data, representation);
}}

bool {p}::getKey(void*, eprosima::fastrtps::rtps::InstanceHandle_t*, bool) {{
  return false;  // no keys
}}

void* {p}::createData() {{ return new {t}(); }}

void {p}::deleteData(void* data) {{ delete static_cast<{t}*>(data); }}

""")
    return "".join(out)


def gen_typeobject_header(name, idl, structs):
    guard = f"RSG_GENERATED_{name.upper()}_TYPEOBJECT_H"
    out = [HEADER.format(idl=idl), f"#ifndef {guard}\n#define {guard}\n\n"]
    out.append("#include <fastrtps/types/TypeIdentifier.h>\n#include <fastrtps/types/TypeObject.h>\n\n")
    out.append(f"/// Registers the TypeObjects of {Path(idl).name}'s structs in Fast DDS 2's TypeObjectFactory, complete\n"
               f"/// and minimal, under their scoped and unqualified names, as fastddsgen 2.3's code does.\n")
    out.append(f"void register{name}Types();\n\n")
    for s in structs:
        out.append(namespace_open(s.scope))
        out.append(f"const eprosima::fastrtps::types::TypeIdentifier* Get{s.name}Identifier(bool complete);\n")
        out.append(f"const eprosima::fastrtps::types::TypeObject* Get{s.name}Object(bool complete);\n")
        out.append(namespace_close(s.scope))
    out.append("\n#endif\n")
    return "".join(out)


def type_identifier_expr(member, complete):
    """The C++ expression of a member's TypeIdentifier, as fastddsgen 2.3 asks the factory for it."""
    kind = member.type
    factory = "TypeObjectFactory::get_instance()"
    if kind.kind == "struct":
        if member.array:
            raise IdlError(f"{member.name}: arrays of structs in a TypeObject are outside rsg's subset")
        return f"*::{kind.name}Identifier_fn({'true' if complete else 'false'})"
    if kind.kind == "sequence":
        raise IdlError(f"{member.name}: sequences in a TypeObject are outside rsg's subset")
    if kind.kind == "string":
        if member.array:
            raise IdlError(f"{member.name}: arrays of strings in a TypeObject are outside rsg's subset")
        return f"*{factory}->get_string_identifier({kind.bound}, false)"
    base = PRIMITIVES[kind.name][2]
    if member.array:
        return f'*{factory}->get_array_identifier("{base}", {{{member.array}}}, {"true" if complete else "false"})'
    return f'*{factory}->get_type_identifier("{base}", false)'


def gen_typeobject_source(name, idl, structs):
    out = [HEADER.format(idl=idl), f'#include "{name}TypeObject.h"\n\n']
    out.append("#include <fastcdr/Cdr.h>\n#include <fastcdr/CdrSizeCalculator.hpp>\n#include <fastcdr/FastBuffer.h>\n"
               "#include <fastrtps/rtps/common/SerializedPayload.h>\n"
               "#include <fastrtps/types/TypeObjectFactory.h>\n#include <fastrtps/utils/md5.h>\n\n#include <type_traits>\n\n")
    out.append("""namespace {

using namespace eprosima::fastrtps::types;

/// fastddsgen 2.3's member flags: all false (no key, optional or external members in rsg's IDL).
void clear_flags(CommonStructMember& common) {
  auto& flags = common.member_flags();
  flags.TRY_CONSTRUCT1(false);
  flags.TRY_CONSTRUCT2(false);
  flags.IS_EXTERNAL(false);
  flags.IS_OPTIONAL(false);
  flags.IS_MUST_UNDERSTAND(false);
  flags.IS_KEY(false);
  flags.IS_DEFAULT(false);
}

/// fastddsgen 2.3 sets no extensibility flag (so the hash is the one a 2.9 peer computes).
void clear_flags(StructTypeFlag& flags) {
  flags.IS_FINAL(false);
  flags.IS_APPENDABLE(false);
  flags.IS_MUTABLE(false);
  flags.IS_NESTED(false);
  flags.IS_AUTOID_HASH(false);
}

/// One member, as fastddsgen 2.3 describes it: its name in a complete object, the first 4 bytes of
/// the name's MD5 in a minimal one.
template <class Member, class Type>
void add_member(Type& type, MemberId id, const TypeIdentifier& member_type, const char* name) {
  Member member;
  member.common().member_id(id);
  clear_flags(member.common());
  member.common().member_type_id(member_type);
  if constexpr (std::is_same_v<Member, CompleteStructMember>) {
    member.detail().name(name);
  } else {
    MD5 hash(name);
    for (int i = 0; i < 4; ++i) member.detail().name_hash()[i] = hash.digest[i];
  }
  type.member_seq().emplace_back(member);
}

/// The equivalence hash: the first 14 bytes of the MD5 of the object's little-endian XCDR1 bytes
/// (XTypes 1.1, 7.3.4.1.1).
void hash(const TypeObject& object, TypeIdentifier& identifier) {
  eprosima::fastcdr::CdrSizeCalculator calculator(eprosima::fastcdr::CdrVersion::XCDRv1);
  size_t alignment = 0;
  eprosima::fastrtps::rtps::SerializedPayload_t payload(
      static_cast<uint32_t>(calculator.calculate_serialized_size(object, alignment) + 4));
  eprosima::fastcdr::FastBuffer buffer(reinterpret_cast<char*>(payload.data), payload.max_size);
  eprosima::fastcdr::Cdr cdr(buffer, eprosima::fastcdr::Cdr::LITTLE_ENDIANNESS, eprosima::fastcdr::CdrVersion::XCDRv1);
  cdr << object;
  payload.length = static_cast<uint32_t>(cdr.get_serialized_data_length());
  MD5 digest;
  digest.update(reinterpret_cast<char*>(payload.data), payload.length);
  digest.finalize();
  for (int i = 0; i < 14; ++i) identifier.equivalence_hash()[i] = digest.digest[i];
}

}  // namespace

""")
    for s in structs:
        ns = namespace_open(s.scope)
        out.append(ns)
        out.append(f"""
const eprosima::fastrtps::types::TypeIdentifier* Get{s.name}Identifier(bool complete) {{
  using namespace eprosima::fastrtps::types;
  const TypeIdentifier* identifier = TypeObjectFactory::get_instance()->get_type_identifier("{s.name}", complete);
  if (identifier != nullptr && (!complete || identifier->_d() == EK_COMPLETE)) return identifier;
  Get{s.name}Object(complete);
  return TypeObjectFactory::get_instance()->get_type_identifier("{s.name}", complete);
}}

const eprosima::fastrtps::types::TypeObject* Get{s.name}Object(bool complete) {{
  using namespace eprosima::fastrtps::types;
  TypeObjectFactory* factory = TypeObjectFactory::get_instance();
  if (const TypeObject* known = factory->get_type_object("{s.name}", complete);
      known != nullptr && (!complete || known->_d() == EK_COMPLETE))
    return known;
  TypeObject object;
  TypeIdentifier identifier;
  if (complete) {{
    object._d(EK_COMPLETE);
    object.complete()._d(TK_STRUCTURE);
    CompleteStructType& type = object.complete().struct_type();
    clear_flags(type.struct_flags());
""")
        for index, member in enumerate(s.members):
            out.append(f'    add_member<CompleteStructMember>(type, {index}, {type_identifier_expr(member, True)}, "{member.name}");\n')
        out.append(f"""    type.header().detail().type_name("{s.name}");
    identifier._d(EK_COMPLETE);
  }} else {{
    object._d(EK_MINIMAL);
    object.minimal()._d(TK_STRUCTURE);
    MinimalStructType& type = object.minimal().struct_type();
    clear_flags(type.struct_flags());
""")
        for index, member in enumerate(s.members):
            out.append(f'    add_member<MinimalStructMember>(type, {index}, {type_identifier_expr(member, False)}, "{member.name}");\n')
        out.append(f"""    identifier._d(EK_MINIMAL);
  }}
  hash(object, identifier);
  factory->add_type_object("{s.name}", &identifier, &object);
  return factory->get_type_object("{s.name}", complete);
}}
""")
        out.append(namespace_close(s.scope))
    out.append(f"\nvoid register{name}Types() {{\n  using eprosima::fastrtps::types::TypeObjectFactory;\n"
               "  TypeObjectFactory* factory = TypeObjectFactory::get_instance();\n")
    for s in structs:
        t = "::" + s.scoped
        for complete in ("true", "false"):
            out.append(f'  factory->add_type_object("{s.scoped}", {t[:-len(s.name)]}Get{s.name}Identifier({complete}),\n'
                       f'                           {t[:-len(s.name)]}Get{s.name}Object({complete}));\n')
    out.append("}\n")
    text = "".join(out)
    # A nested struct's identifier: its own Get<Name>Identifier in its namespace.
    for s in structs:
        text = text.replace(f"*::{s.scoped}Identifier_fn(", f"*::{'::'.join(s.scope + ['Get' + s.name])}Identifier(")
    return text


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--typeobject", action="store_true", help="also <name>TypeObject.h/.cxx")
    parser.add_argument("idl", type=Path)
    parser.add_argument("outdir", type=Path)
    args = parser.parse_args()
    try:
        structs, consts = Parser(args.idl.read_text()).parse()
    except (IdlError, ValueError) as error:
        sys.exit(f"{args.idl}: {error}")
    if not structs:
        sys.exit(f"{args.idl}: no struct")
    name = args.idl.stem
    idl = args.idl.name
    sizes = Sizes(structs)
    files = {
        f"{name}.h": gen_types_header(name, idl, structs, consts),
        f"{name}.cxx": gen_types_source(name, idl, structs, sizes),
        f"{name}PubSubTypes.h": gen_pubsub_header(name, idl, structs, sizes),
        f"{name}PubSubTypes.cxx": gen_pubsub_source(name, idl, structs),
    }
    if args.typeobject:
        try:
            files[f"{name}TypeObject.h"] = gen_typeobject_header(name, idl, structs)
            files[f"{name}TypeObject.cxx"] = gen_typeobject_source(name, idl, structs)
        except IdlError as error:
            sys.exit(f"{args.idl}: {error}")
    args.outdir.mkdir(parents=True, exist_ok=True)
    for file, text in files.items():
        path = args.outdir / file
        # Unchanged files keep their time stamps: nothing that includes them recompiles.
        if not path.exists() or path.read_text() != text:
            path.write_text(text)


if __name__ == "__main__":
    main()
