// The parser's declarations: POUs (FUNCTION, FUNCTION_BLOCK, PROGRAM), TYPE
// blocks, VAR sections and their declarations, type specs (arrays, strings,
// structures, enumerations, subranges) and initial values.
#include <string>

#include "runtime/st/parser_state.hpp"

namespace syncplc::st::parsing {

Pou Parser::pou() {
  const std::size_t start = pos_;
  Pou p;
  p.loc = cur().loc;
  if (cur().comment_directly_before) p.doc = cur().comment_before;
  const K kw = advance().kind;
  p.kind = kw == K::KwFunction ? PouKind::Function : kw == K::KwFunctionBlock ? PouKind::FunctionBlock
                                                                               : PouKind::Program;
  const K end = kw == K::KwFunction ? K::KwEndFunction : kw == K::KwFunctionBlock ? K::KwEndFunctionBlock
                                                                                   : K::KwEndProgram;
  p.name = name("the POU's name");
  if (p.kind == PouKind::Function) {
    if (expect(K::Colon, "':' and the function's return type")) p.return_type.push_back(type_spec());
  }
  panic_ = false;
  for (;;) {
    if (is_section_start(cur().kind)) {
      p.sections.push_back(var_section());
    } else if (const K misspelt = misspelt_section(); misspelt != K::End) {
      // Reported with its suggestion, then read as the section it most likely is.
      expected("a VAR section or a statement");
      panic_ = false;
      p.sections.push_back(var_section(misspelt));
    } else {
      break;
    }
  }
  p.body = statement_list();
  if (!accept(end)) {
    expected(describe(end));
    // Skip to this POU's end when it is there; stop at the next POU otherwise.
    while (!at(K::End) && !at(end) && !is_pou_start(cur().kind)) advance();
    accept(end);
  }
  accept(K::Semicolon);  // tolerated after END_… as many tools write it
  if (p.doc.empty())
    for (std::size_t i = start + 1; i < pos_ && i < tokens_.size(); ++i)
      if (!tokens_[i].comment_before.empty()) {
        p.doc = tokens_[i].comment_before;
        break;
      }
  return p;
}

void Parser::type_block() {
  advance();  // TYPE
  while (!at(K::End) && !at(K::KwEndType) && !is_pou_start(cur().kind)) {
    panic_ = false;
    TypeDecl d;
    d.loc = cur().loc;
    d.name = name("a type name or END_TYPE");
    if (!d.name.empty() && expect(K::Colon, "':'")) {
      d.type = type_spec();
      if (accept(K::Assign)) d.init = initializer();
      if (!panic_) {
        expect(K::Semicolon, "';'");
      }
    }
    if (panic_) {
      while (!at(K::End) && !at(K::Semicolon) && !at(K::KwEndType) && !is_pou_start(cur().kind)) advance();
      accept(K::Semicolon);
    } else {
      unit_.types.push_back(std::move(d));
    }
  }
  panic_ = false;
  expect(K::KwEndType, "END_TYPE");
  accept(K::Semicolon);
}

// A name close to a section keyword followed by what starts a section's
// content (VAR_INPT x : …, VAR_OUTPT RETAIN): which section it means, or End.
// No statement starts with two names, so this never takes a statement.
K Parser::misspelt_section() const {
  if (!at(K::Identifier)) return K::End;
  const K next = peek(1).kind;
  if (next != K::Identifier && next != K::KwConstant && next != K::KwRetain && next != K::KwNonRetain &&
      next != K::KwPersistent)
    return K::End;
  static const std::vector<std::string_view> sections = {"VAR", "VAR_INPUT", "VAR_OUTPUT", "VAR_IN_OUT",
                                                         "VAR_TEMP", "VAR_EXTERNAL", "VAR_GLOBAL"};
  const std::string near = closest_name(upper(cur().text), sections);
  return near.empty() ? K::End : keyword_kind(near);
}

// From a VAR… keyword (or, with `as`, from a misspelt one) to END_VAR.
VarSection Parser::var_section(K as) {
  VarSection s;
  s.loc = cur().loc;
  const K kw = advance().kind;
  switch (as != K::End ? as : kw) {
    case K::KwVarInput: s.kind = VarSectionKind::Input; break;
    case K::KwVarOutput: s.kind = VarSectionKind::Output; break;
    case K::KwVarInOut: s.kind = VarSectionKind::InOut; break;
    case K::KwVarTemp: s.kind = VarSectionKind::Temp; break;
    case K::KwVarExternal: s.kind = VarSectionKind::External; break;
    case K::KwVarGlobal: s.kind = VarSectionKind::Global; break;
    default: s.kind = VarSectionKind::Var; break;
  }
  for (;;) {
    if (accept(K::KwConstant)) s.constant = true;
    else if (accept(K::KwRetain)) s.retain = true;
    else if (accept(K::KwNonRetain)) s.non_retain = true;
    else if (accept(K::KwPersistent)) s.persistent = true;
    else break;
  }
  while (!at(K::End) && !at(K::KwEndVar) && !is_section_start(cur().kind) && !is_pou_start(cur().kind) &&
         !is_end_keyword(cur().kind) && !is_statement_start(cur().kind)) {
    panic_ = false;
    const std::size_t before = pos_;
    VarDecl d = var_decl(true);
    if (panic_) {
      while (!at(K::End) && !at(K::Semicolon) && !at(K::KwEndVar) && !is_pou_start(cur().kind) &&
             !is_end_keyword(cur().kind))
        advance();
      accept(K::Semicolon);
    } else {
      s.decls.push_back(std::move(d));
    }
    if (pos_ == before) advance();
  }
  panic_ = false;
  expect(K::KwEndVar, "END_VAR");
  panic_ = false;
  return s;
}

// a, b AT %IX0.0 : TYPE := init;
VarDecl Parser::var_decl(bool allow_address) {
  VarDecl d;
  d.loc = cur().loc;
  do {
    d.name_locs.push_back(cur().loc);
    std::string n = name(d.names.empty() ? "a variable name or END_VAR" : "a variable name");
    if (n.empty()) return d;
    d.names.push_back(std::move(n));
  } while (accept(K::Comma));
  if (allow_address && accept(K::KwAt)) {
    if (at(K::DirectAddress)) {
      d.address = advance().text;
    } else {
      expected("a direct address (e.g. %IX0.0)");
      return d;
    }
  }
  if (!expect(K::Colon, "':' and a type")) return d;
  d.type = type_spec();
  if (panic_) return d;
  if (accept(K::Assign)) d.init = initializer();
  if (panic_) return d;
  expect(K::Semicolon, "';'");
  return d;
}

TypeSpec Parser::type_spec() {
  Depth guard(*this);
  TypeSpec t;
  t.loc = cur().loc;
  if (too_deep()) return t;
  if (accept(K::KwArray)) {
    t.kind = TypeKind::Array;
    if (!expect(K::LBracket, "'[' and the array's bounds")) return t;
    do t.dims.push_back(subrange());
    while (!panic_ && accept(K::Comma));
    if (panic_ || !expect(K::RBracket, "']'") || !expect(K::KwOf, "OF")) return t;
    t.element.push_back(type_spec());
    return t;
  }
  if (at(K::KwString) || at(K::KwWString)) {
    t.kind = TypeKind::String;
    t.wide = advance().kind == K::KwWString;
    t.name = t.wide ? "WSTRING" : "STRING";
    // STRING[80] as IEC writes it; STRING(80) as CODESYS does.
    if (accept(K::LBracket)) {
      t.length = expression();
      expect(K::RBracket, "']'");
    } else if (accept(K::LParen)) {
      t.length = expression();
      expect(K::RParen, "')'");
    }
    return t;
  }
  if (accept(K::KwStruct)) {
    t.kind = TypeKind::Struct;
    while (!at(K::End) && !at(K::KwEndStruct) && !is_pou_start(cur().kind) && !at(K::KwEndType)) {
      panic_ = false;
      const std::size_t before = pos_;
      VarDecl d = var_decl(false);
      if (panic_) {
        while (!at(K::End) && !at(K::Semicolon) && !at(K::KwEndStruct) && !at(K::KwEndType) &&
               !is_pou_start(cur().kind))
          advance();
        accept(K::Semicolon);
      } else {
        t.members.push_back(std::move(d));
      }
      if (pos_ == before) advance();
    }
    panic_ = false;
    expect(K::KwEndStruct, "END_STRUCT");
    return t;
  }
  if (at(K::LParen)) return enumeration(t);
  if (!at(K::Identifier)) {
    expected("a type");
    return t;
  }
  t.name = advance().text;
  if (at(K::LParen)) {
    // INT (0..100) is a subrange; INT (a := 1, b) an enumeration on INT.
    const K k1 = peek(1).kind, k2 = peek(2).kind;
    const bool enumerated = k1 == K::Identifier && (k2 == K::Assign || k2 == K::Comma || k2 == K::RParen);
    if (enumerated) return enumeration(t);
    t.kind = TypeKind::Subrange;
    advance();
    t.dims.push_back(subrange());
    if (!panic_) expect(K::RParen, "')'");
  }
  return t;
}

TypeSpec Parser::enumeration(TypeSpec& t) {
  t.kind = TypeKind::Enum;
  advance();  // (
  do {
    Enumerator e;
    e.loc = cur().loc;
    e.name = name("an enumeration value");
    if (e.name.empty()) return t;
    if (accept(K::Assign)) e.value = expression();
    t.enumerators.push_back(std::move(e));
  } while (!panic_ && accept(K::Comma));
  if (!panic_) expect(K::RParen, "',' or ')'");
  return t;
}

Subrange Parser::subrange() {
  Subrange r;
  r.loc = cur().loc;
  r.low = expression();
  if (panic_) return r;
  if (!expect(K::DotDot, "'..'")) return r;
  r.high = expression();
  return r;
}

Initializer Parser::initializer() {
  Depth guard(*this);
  Initializer init;
  init.loc = cur().loc;
  if (too_deep()) return init;
  if (accept(K::LBracket)) {
    init.kind = InitKind::Array;
    do {
      ArrayInitElement e;
      e.loc = cur().loc;
      if (at(K::Integer) && peek(1).kind == K::LParen) {
        e.repeat = primary();
        advance();  // (
        if (!at(K::RParen)) e.value = initializer();
        if (!panic_) expect(K::RParen, "')'");
      } else {
        e.value = initializer();
      }
      init.elements.push_back(std::move(e));
    } while (!panic_ && accept(K::Comma));
    if (!panic_) expect(K::RBracket, "',' or ']'");
    return init;
  }
  if (at(K::LParen) && peek(1).kind == K::Identifier && peek(2).kind == K::Assign) {
    init.kind = InitKind::Struct;
    advance();
    do {
      FieldInit f;
      f.loc = cur().loc;
      f.name = name("a field name");
      if (f.name.empty() || !expect(K::Assign, "':='")) return init;
      f.value = initializer();
      init.fields.push_back(std::move(f));
    } while (!panic_ && accept(K::Comma));
    if (!panic_) expect(K::RParen, "',' or ')'");
    return init;
  }
  init.kind = InitKind::Expr;
  init.expr = expression();
  return init;
}

}  // namespace syncplc::st::parsing
