#include "runtime/st/parser.hpp"

#include <initializer_list>
#include <string>

#include <fmt/format.h>

#include "runtime/st/lexer.hpp"

namespace syncplc::st {

namespace {

using K = TokenKind;

bool is_end_keyword(K k) {
  switch (k) {
    case K::KwEndFunction: case K::KwEndFunctionBlock: case K::KwEndProgram: case K::KwEndType:
    case K::KwEndStruct: case K::KwEndVar: case K::KwEndIf: case K::KwEndCase: case K::KwEndFor:
    case K::KwEndWhile: case K::KwEndRepeat:
      return true;
    default:
      return false;
  }
}

bool is_statement_end(K k) {
  return k == K::KwEndIf || k == K::KwEndCase || k == K::KwEndFor || k == K::KwEndWhile || k == K::KwEndRepeat;
}

bool is_pou_start(K k) {
  return k == K::KwFunction || k == K::KwFunctionBlock || k == K::KwProgram || k == K::KwType ||
         (k == K::KwVarGlobal);
}

bool is_section_start(K k) {
  return k == K::KwVar || k == K::KwVarInput || k == K::KwVarOutput || k == K::KwVarInOut || k == K::KwVarTemp ||
         k == K::KwVarExternal || k == K::KwVarGlobal;
}

bool is_statement_start(K k) {
  return k == K::KwIf || k == K::KwCase || k == K::KwFor || k == K::KwWhile || k == K::KwRepeat ||
         k == K::KwExit || k == K::KwContinue || k == K::KwReturn;
}

// The keywords a misspelt word is compared with for "did you mean".
const std::vector<std::string_view>& keyword_spellings() {
  static const std::vector<std::string_view> words = [] {
    std::vector<std::string_view> w;
    for (int k = static_cast<int>(K::KwFunction); k <= static_cast<int>(K::KwFalse); ++k)
      w.push_back(describe(static_cast<K>(k)));
    return w;
  }();
  return words;
}

class Parser {
 public:
  Parser(std::vector<Token> tokens, const SourceFile& file, StDiagnostics& diags) : diags_(diags) {
    unit_.file = file;
    // Pragmas are skipped here, with a note; a comment before one stays with the next token.
    tokens_.reserve(tokens.size());
    std::string carried;
    bool carried_directly_before = false;
    for (auto& t : tokens) {
      if (t.kind == K::Pragma) {
        diags_.note(t.loc, fmt::format("pragma '{}' ignored",
                                       t.text.size() > 60 ? t.text.substr(0, 60) + "…" : t.text));
        if (!t.comment_before.empty()) {
          carried = std::move(t.comment_before);
          carried_directly_before = t.comment_directly_before;
        }
        continue;
      }
      if (t.comment_before.empty() && !carried.empty()) {
        t.comment_before = std::move(carried);
        t.comment_directly_before = carried_directly_before;
      }
      carried.clear();
      tokens_.push_back(std::move(t));
    }
  }

  CompilationUnit run() {
    while (!at(K::End)) {
      panic_ = false;
      switch (cur().kind) {
        case K::KwFunction: case K::KwFunctionBlock: case K::KwProgram:
          unit_.pous.push_back(pou());
          break;
        case K::KwType:
          type_block();
          break;
        case K::KwVarGlobal:
          unit_.globals.push_back(var_section());
          break;
        default:
          expected("FUNCTION, FUNCTION_BLOCK, PROGRAM, TYPE or VAR_GLOBAL");
          advance();
          while (!at(K::End) && !is_pou_start(cur().kind)) advance();
      }
    }
    return std::move(unit_);
  }

 private:
  // ---- Tokens ----
  const Token& cur() const { return tokens_[pos_]; }
  const Token& peek(std::size_t ahead) const {
    return tokens_[std::min(pos_ + ahead, tokens_.size() - 1)];
  }
  bool at(K k) const { return cur().kind == k; }
  const Token& advance() {
    const Token& t = tokens_[pos_];
    if (pos_ + 1 < tokens_.size()) ++pos_;
    return t;
  }
  bool accept(K k) {
    if (!at(k)) return false;
    advance();
    return true;
  }

  // "expected X, found Y" at the current token, once until the parser has
  // resynchronised; none for a token the lexer already reported.
  void expected(std::string_view what) {
    if (!panic_ && !too_deep_ && !after_lexical_error()) {
      std::string msg = fmt::format("expected {}, found {}", what, describe(cur()));
      if (cur().kind == K::Identifier)
        if (const std::string near = closest_name(upper(cur().text), keyword_spellings()); !near.empty())
          msg += fmt::format(" (did you mean {}?)", near);
      diags_.error(cur().loc, std::move(msg));
    }
    panic_ = true;
  }
  // The lexer reported the token here or the one just before: a syntax
  // error about it would only repeat that.
  bool after_lexical_error() const {
    return cur().kind == K::Error || (pos_ > 0 && tokens_[pos_ - 1].kind == K::Error);
  }
  bool expect(K k, std::string_view what = {}) {
    if (accept(k)) return true;
    expected(what.empty() ? describe(k) : what);
    return false;
  }
  // A statement's closing keyword: a different END_ of a statement is taken
  // as the misspelt one (one error, not one per enclosing block).
  void expect_end(K k) {
    if (accept(k)) {
      expect_semicolon();
      return;
    }
    expected(describe(k));
    if (is_statement_end(cur().kind)) {
      advance();
      accept(K::Semicolon);
    }
  }
  void expect_semicolon() {
    if (accept(K::Semicolon)) return;
    // Reported without skipping: the next statement is most likely fine.
    expected("';'");
    panic_ = false;
  }

  std::string name(std::string_view what) {
    if (at(K::Identifier)) return advance().text;
    expected(what);
    return {};
  }

  // Too deep: one error, then the rest of the file is skipped (the tree
  // stays within the limit for every later pass).
  struct Depth {
    Parser& p;
    explicit Depth(Parser& parser) : p(parser) { p.enter(); }
    ~Depth() { --p.depth_; }
    Depth(const Depth&) = delete;
    Depth& operator=(const Depth&) = delete;
  };
  void enter() {
    if (++depth_ > kMaxNesting && !too_deep_) {
      too_deep_ = true;
      diags_.error(cur().loc, fmt::format("nesting deeper than {} levels (expressions, statements and operator "
                                          "chains together); the rest of the file is not parsed", kMaxNesting));
    }
    if (too_deep_) pos_ = tokens_.size() - 1;
  }
  bool too_deep() const { return too_deep_; }

  // ---- Program organisation units ----
  Pou pou() {
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

  void type_block() {
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
  K misspelt_section() const {
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
  VarSection var_section(K as = K::End) {
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
  VarDecl var_decl(bool allow_address) {
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

  // ---- Types ----
  TypeSpec type_spec() {
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

  TypeSpec enumeration(TypeSpec& t) {
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

  Subrange subrange() {
    Subrange r;
    r.loc = cur().loc;
    r.low = expression();
    if (panic_) return r;
    if (!expect(K::DotDot, "'..'")) return r;
    r.high = expression();
    return r;
  }

  // ---- Initial values ----
  Initializer initializer() {
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

  // ---- Statements ----

  // Whether the tokens here start a CASE label (1:, 1, 2:, 1..5:, Red:, Colour#Red:, -1:).
  bool at_case_label() const {
    switch (cur().kind) {
      case K::Integer: case K::Minus: case K::Plus: case K::Real: case K::Duration: case K::String:
        return true;
      case K::Identifier: {
        const K k = peek(1).kind;
        return k == K::Colon || k == K::Comma || k == K::DotDot || k == K::Hash;
      }
      default:
        return false;
    }
  }

  std::vector<Statement> statement_list(bool in_case = false) {
    std::vector<Statement> list;
    bool after_error = false;
    for (;;) {
      const K k = cur().kind;
      // The END_VAR of a misspelt section (VAR_INPT x : INT; END_VAR), already
      // reported: skipped rather than taken as the end of the body.
      if (after_error && k == K::KwEndVar) {
        advance();
        accept(K::Semicolon);
        continue;
      }
      if (k == K::End || is_end_keyword(k) || k == K::KwElsif || k == K::KwElse || k == K::KwUntil ||
          is_pou_start(k) || (in_case && at_case_label()))
        break;
      if (is_section_start(k)) {
        expected("a statement (variable sections go before the first statement)");
        var_section();
        continue;
      }
      const std::size_t before = pos_;
      Statement s = statement();
      after_error = panic_;
      if (panic_) {
        recover();
      } else {
        list.push_back(std::move(s));
      }
      if (pos_ == before) advance();
    }
    return list;
  }

  // After a syntax error in a statement: skip to the next ';' or the THEN,
  // DO or OF that ends a statement's head (taken), or to a keyword that
  // starts or ends a statement (left for the list).
  void recover() {
    while (!at(K::End)) {
      const K k = cur().kind;
      if (k == K::Semicolon || k == K::KwThen || k == K::KwDo || k == K::KwOf) {
        advance();
        break;
      }
      if (is_end_keyword(k) || is_statement_start(k) || k == K::KwElsif || k == K::KwElse || k == K::KwUntil ||
          is_pou_start(k) || is_section_start(k))
        break;
      advance();
    }
    panic_ = false;
  }

  Statement statement() {
    Depth guard(*this);
    Statement s;
    s.loc = cur().loc;
    if (too_deep()) return s;
    switch (cur().kind) {
      case K::Semicolon:
        advance();
        s.kind = StmtKind::Empty;
        return s;
      case K::KwIf: return if_statement(s);
      case K::KwCase: return case_statement(s);
      case K::KwFor: return for_statement(s);
      case K::KwWhile: return while_statement(s);
      case K::KwRepeat: return repeat_statement(s);
      case K::KwExit: advance(); s.kind = StmtKind::Exit; expect_semicolon(); return s;
      case K::KwContinue: advance(); s.kind = StmtKind::Continue; expect_semicolon(); return s;
      case K::KwReturn: advance(); s.kind = StmtKind::Return; expect_semicolon(); return s;
      case K::Identifier: break;
      default:
        expected("a statement");
        return s;
    }
    const Token& first = cur();
    Expr e = variable_or_call();
    if (panic_) return s;
    if (accept(K::Assign)) {
      s.kind = StmtKind::Assign;
      s.target = std::move(e);
      s.value = expression();
      if (!panic_) expect_semicolon();
      return s;
    }
    if (e.kind == ExprKind::Call) {
      s.kind = StmtKind::Call;
      s.value = std::move(e);
      expect_semicolon();
      return s;
    }
    if (!panic_ && !too_deep_ && !after_lexical_error()) {
      std::string msg = fmt::format("expected ':=' or a call after '{}', found {}", first.text, describe(cur()));
      if (e.kind == ExprKind::Name)
        if (const std::string near = closest_name(upper(first.text), keyword_spellings()); !near.empty())
          msg += fmt::format(" (did you mean {}?)", near);
      diags_.error(cur().loc, std::move(msg));
    }
    panic_ = true;
    return s;
  }

  Statement if_statement(Statement& s) {
    s.kind = StmtKind::If;
    do {
      IfBranch b;
      b.loc = cur().loc;
      advance();  // IF / ELSIF
      b.condition = expression();
      if (!panic_) expect(K::KwThen, "THEN");
      if (panic_) {
        recover();
        accept(K::KwThen);
      }
      b.body = statement_list();
      s.branches.push_back(std::move(b));
    } while (at(K::KwElsif));
    if (accept(K::KwElse)) {
      s.has_else = true;
      s.else_body = statement_list();
    }
    expect_end(K::KwEndIf);
    panic_ = false;
    return s;
  }

  Statement case_statement(Statement& s) {
    s.kind = StmtKind::Case;
    advance();
    s.value = expression();
    if (!panic_) expect(K::KwOf, "OF");
    if (panic_) {
      recover();
      accept(K::KwOf);
    }
    while (at_case_label()) {
      CaseBranch b;
      b.loc = cur().loc;
      do {
        CaseLabel l;
        l.loc = cur().loc;
        l.low = expression();
        if (!panic_ && accept(K::DotDot)) l.high = expression();
        b.labels.push_back(std::move(l));
      } while (!panic_ && accept(K::Comma));
      if (!panic_) expect(K::Colon, "':' after the case labels");
      if (panic_) recover();
      b.body = statement_list(true);
      s.cases.push_back(std::move(b));
    }
    if (accept(K::KwElse)) {
      s.has_else = true;
      s.else_body = statement_list();
    }
    expect_end(K::KwEndCase);
    panic_ = false;
    return s;
  }

  Statement for_statement(Statement& s) {
    s.kind = StmtKind::For;
    advance();
    s.target.loc = cur().loc;
    s.target.name = name("the FOR loop's control variable");
    s.target.kind = ExprKind::Name;
    if (!panic_) expect(K::Assign, "':='");
    if (!panic_) s.value = expression();
    if (!panic_) expect(K::KwTo, "TO");
    if (!panic_) s.to = expression();
    if (!panic_ && accept(K::KwBy)) s.by = expression();
    if (!panic_) expect(K::KwDo, "DO");
    if (panic_) {
      recover();
      accept(K::KwDo);
    }
    s.body = statement_list();
    expect_end(K::KwEndFor);
    panic_ = false;
    return s;
  }

  Statement while_statement(Statement& s) {
    s.kind = StmtKind::While;
    advance();
    s.value = expression();
    if (!panic_) expect(K::KwDo, "DO");
    if (panic_) {
      recover();
      accept(K::KwDo);
    }
    s.body = statement_list();
    expect_end(K::KwEndWhile);
    panic_ = false;
    return s;
  }

  Statement repeat_statement(Statement& s) {
    s.kind = StmtKind::Repeat;
    advance();
    s.body = statement_list();
    if (expect(K::KwUntil, "UNTIL")) s.value = expression();
    if (panic_) recover();
    expect_end(K::KwEndRepeat);
    panic_ = false;
    return s;
  }

  // ---- Expressions ----
  static int precedence(K k) {
    switch (k) {
      case K::KwOr: return 1;
      case K::KwXor: return 2;
      case K::KwAnd: case K::Ampersand: return 3;
      case K::Equal: case K::NotEqual: return 4;
      case K::Less: case K::Greater: case K::LessEqual: case K::GreaterEqual: return 5;
      case K::Plus: case K::Minus: return 6;
      case K::Star: case K::Slash: case K::KwMod: return 7;
      case K::Power: return 8;
      default: return 0;
    }
  }
  static BinaryOp binary_op(K k) {
    switch (k) {
      case K::KwOr: return BinaryOp::Or;
      case K::KwXor: return BinaryOp::Xor;
      case K::KwAnd: case K::Ampersand: return BinaryOp::And;
      case K::Equal: return BinaryOp::Equal;
      case K::NotEqual: return BinaryOp::NotEqual;
      case K::Less: return BinaryOp::Less;
      case K::Greater: return BinaryOp::Greater;
      case K::LessEqual: return BinaryOp::LessEqual;
      case K::GreaterEqual: return BinaryOp::GreaterEqual;
      case K::Plus: return BinaryOp::Add;
      case K::Minus: return BinaryOp::Subtract;
      case K::Star: return BinaryOp::Multiply;
      case K::Slash: return BinaryOp::Divide;
      case K::KwMod: return BinaryOp::Mod;
      default: return BinaryOp::Power;
    }
  }

  Expr expression() {
    Depth guard(*this);
    if (too_deep()) return {};
    return binary(1);
  }

  // Precedence climbing; every operator is left-associative (IEC 61131-3
  // 3rd edition, table 71), each one applied counts as a level of nesting.
  Expr binary(int min_prec) {
    Expr lhs = unary();
    int chain = 0;
    while (!panic_ && !too_deep()) {
      const int prec = precedence(cur().kind);
      if (prec == 0 || prec < min_prec) break;
      Expr e;
      e.kind = ExprKind::Binary;
      e.loc = cur().loc;
      e.binary_op = binary_op(advance().kind);
      Expr rhs = binary(prec + 1);
      ++chain;
      enter();
      e.operands.push_back(std::move(lhs));
      e.operands.push_back(std::move(rhs));
      lhs = std::move(e);
    }
    depth_ -= chain;
    return lhs;
  }

  // Negation, unary plus and NOT bind tighter than ** (3rd edition, table 71:
  // precedence 8 against 7), so -2 ** 2 is (-2) ** 2.
  Expr unary() {
    if (at(K::Minus) || at(K::Plus) || at(K::KwNot)) {
      Depth guard(*this);
      if (too_deep()) return {};
      Expr e;
      e.kind = ExprKind::Unary;
      e.loc = cur().loc;
      const K k = advance().kind;
      e.unary_op = k == K::Minus ? UnaryOp::Negate : k == K::Plus ? UnaryOp::Plus : UnaryOp::Not;
      e.operands.push_back(unary());
      return e;
    }
    return postfix(primary());
  }

  Expr variable_or_call() { return postfix(primary()); }

  // a.b[i, j].c, w.3, f(…)
  Expr postfix(Expr base) {
    int chain = 0;
    while (!panic_ && !too_deep()) {
      if (at(K::Dot)) {
        const SourceLoc loc = advance().loc;
        Expr e;
        e.loc = loc;
        if (at(K::Integer) && cur().type_prefix.empty()) {
          e.kind = ExprKind::BitAccess;
          const std::uint64_t bit = advance().int_value;
          e.bit = bit > 63 ? 64 : static_cast<int>(bit);  // the checker reports a bit beyond the type
        } else if (at(K::Identifier)) {
          e.kind = ExprKind::Member;
          e.name = advance().text;
        } else {
          expected("a member name or a bit number after '.'");
          break;
        }
        e.operands.push_back(std::move(base));
        base = std::move(e);
      } else if (at(K::LBracket)) {
        Expr e;
        e.kind = ExprKind::Index;
        e.loc = advance().loc;
        e.operands.push_back(std::move(base));
        do e.operands.push_back(expression());
        while (!panic_ && accept(K::Comma));
        if (!panic_) expect(K::RBracket, "',' or ']'");
        base = std::move(e);
      } else if (at(K::LParen) && (base.kind == ExprKind::Index || base.kind == ExprKind::Member)) {
        // axes[2](…): an FB instance reached through an array or a structure.
        Expr e;
        e.kind = ExprKind::Call;
        e.loc = base.loc;
        e.operands.push_back(std::move(base));
        call_arguments(e);
        base = std::move(e);
      } else if (at(K::Caret)) {
        if (!panic_) diags_.error(cur().loc, "pointer dereference '^' is not supported (no pointers in syncplc's ST)");
        panic_ = true;
        break;
      } else {
        break;
      }
      ++chain;
      enter();
    }
    depth_ -= chain;
    return base;
  }

  static Literal literal_of(const Token& t) {
    Literal l;
    l.type_prefix = t.type_prefix;
    l.negative = t.negative;
    switch (t.kind) {
      case K::Integer:
        l.kind = t.type_prefix == "BOOL" ? LiteralKind::Bool : LiteralKind::Integer;
        l.int_value = t.int_value;
        break;
      case K::Real: l.kind = LiteralKind::Real; l.real_value = t.real_value; break;
      case K::Duration: l.kind = LiteralKind::Duration; l.duration_ns = t.duration_ns; break;
      case K::Date: l.kind = LiteralKind::Date; l.text = t.str_value; break;
      case K::TimeOfDay: l.kind = LiteralKind::TimeOfDay; l.text = t.str_value; break;
      case K::DateAndTime: l.kind = LiteralKind::DateAndTime; l.text = t.str_value; break;
      case K::String: l.kind = LiteralKind::String; l.text = t.str_value; break;
      case K::WString: l.kind = LiteralKind::WString; l.text = t.str_value; break;
      case K::KwTrue: case K::KwFalse:
        l.kind = LiteralKind::Bool;
        l.int_value = t.kind == K::KwTrue;
        break;
      default: break;
    }
    return l;
  }

  Expr primary() {
    Expr e;
    e.loc = cur().loc;
    switch (cur().kind) {
      case K::Integer: case K::Real: case K::Duration: case K::Date: case K::TimeOfDay: case K::DateAndTime:
      case K::String: case K::WString: case K::KwTrue: case K::KwFalse:
        e.kind = ExprKind::Literal;
        e.literal = literal_of(advance());
        return e;
      case K::Error:
        // Reported by the lexer; stands for a value so the rest still parses.
        advance();
        return e;
      case K::LParen: {
        advance();
        Expr inner = expression();
        if (!panic_) expect(K::RParen, "')'");
        return inner;
      }
      case K::Identifier: break;
      default:
        expected("an expression");
        return e;
    }
    e.name = advance().text;
    if (at(K::Hash)) {
      // Colour#Red: an enumeration value with its type.
      advance();
      e.kind = ExprKind::EnumValue;
      e.type_name = std::move(e.name);
      e.name = name("an enumeration value after '#'");
      return e;
    }
    if (!at(K::LParen)) {
      e.kind = ExprKind::Name;
      return e;
    }
    e.kind = ExprKind::Call;
    call_arguments(e);
    return e;
  }

  // (…) after a callee: '(' [argument {',' argument}] ')'.
  void call_arguments(Expr& e) {
    advance();  // (
    if (accept(K::RParen)) return;
    do {
      e.args.push_back(argument());
    } while (!panic_ && accept(K::Comma));
    if (!panic_) expect(K::RParen, "',' or ')'");
  }

  // x, IN := x, Q => y, NOT Q => y, Q =>
  Argument argument() {
    Argument a;
    a.loc = cur().loc;
    const bool negated_output = at(K::KwNot) && peek(1).kind == K::Identifier && peek(2).kind == K::OutputAssign;
    if (negated_output) advance();
    if (at(K::Identifier) && (peek(1).kind == K::Assign || peek(1).kind == K::OutputAssign)) {
      a.name = advance().text;
      a.output = advance().kind == K::OutputAssign;
      a.negated = negated_output;
      if (a.output && (at(K::Comma) || at(K::RParen))) return a;  // output left unconnected
      a.value = a.output ? variable_or_call() : expression();
      return a;
    }
    a.value = expression();
    return a;
  }

  std::vector<Token> tokens_;
  std::size_t pos_ = 0;
  StDiagnostics& diags_;
  CompilationUnit unit_;
  bool panic_ = false;
  int depth_ = 0;
  bool too_deep_ = false;
};

}  // namespace

ParseResult parse(std::string_view source, const SourceFile& file) {
  ParseResult r;
  std::vector<Token> tokens = lex(source, file, r.diagnostics);
  r.unit = Parser(std::move(tokens), file, r.diagnostics).run();
  return r;
}

}  // namespace syncplc::st
