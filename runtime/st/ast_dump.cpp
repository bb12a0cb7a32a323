#include "runtime/st/ast_dump.hpp"

#include <fmt/format.h>

namespace syncplc::st {

namespace {

std::string at(const SourceLoc& loc) { return fmt::format("@{}:{}", loc.line, loc.col); }

// A string literal as ST writes it, so the dump shows escapes unambiguously.
std::string quoted(const std::string& s, char quote) {
  std::string out(1, quote);
  for (char c : s) {
    const auto u = static_cast<unsigned char>(c);
    if (c == quote || c == '$') {
      out += '$';
      out += c;
    } else if (c == '\n') {
      out += "$N";
    } else if (c == '\t') {
      out += "$T";
    } else if (c == '\r') {
      out += "$R";
    } else if (c == '\f') {
      out += "$P";
    } else if (u < 0x20 || u == 0x7f) {
      out += fmt::format("${:02X}", u);
    } else {
      out += c;
    }
  }
  return out + quote;
}

std::string literal(const Literal& l) {
  const std::string prefix = l.type_prefix.empty() ? "" : l.type_prefix + "#";
  const std::string sign = l.negative ? "-" : "";
  switch (l.kind) {
    case LiteralKind::Integer: return prefix + sign + std::to_string(l.int_value);
    case LiteralKind::Bool: return prefix + (l.int_value ? "TRUE" : "FALSE");
    case LiteralKind::Real: {
      std::string v = fmt::format("{}", l.real_value);
      if (v.find_first_of(".eEn") == std::string::npos) v += ".0";
      return prefix + sign + v;
    }
    case LiteralKind::Duration: return prefix + std::to_string(l.duration_ns) + "ns";
    case LiteralKind::Date:
    case LiteralKind::TimeOfDay:
    case LiteralKind::DateAndTime: return prefix + l.text;
    case LiteralKind::String: return prefix + quoted(l.text, '\'');
    case LiteralKind::WString: return prefix + quoted(l.text, '"');
  }
  return "?";
}

void expr(std::string& out, const Expr& e);

void argument(std::string& out, const Argument& a) {
  if (a.name.empty()) return expr(out, a.value);
  out += a.output ? "(=> " : "(:= ";
  if (a.negated) out += "NOT ";
  out += a.name;
  if (a.value.kind != ExprKind::None) {
    out += ' ';
    expr(out, a.value);
  }
  out += ')';
}

void expr(std::string& out, const Expr& e) {
  switch (e.kind) {
    case ExprKind::None: out += '_'; return;
    case ExprKind::Literal: out += literal(e.literal); return;
    case ExprKind::Name: out += e.name; return;
    case ExprKind::EnumValue: out += e.type_name + "#" + e.name; return;
    case ExprKind::Member:
      out += "(. ";
      expr(out, e.operands.at(0));
      out += " " + e.name + ")";
      return;
    case ExprKind::BitAccess:
      out += "(.bit ";
      expr(out, e.operands.at(0));
      out += " " + std::to_string(e.bit) + ")";
      return;
    case ExprKind::Index:
      out += "([]";
      for (const auto& o : e.operands) {
        out += ' ';
        expr(out, o);
      }
      out += ')';
      return;
    case ExprKind::Call:
      out += "(call ";
      if (e.name.empty() && !e.operands.empty()) {
        expr(out, e.operands[0]);
      } else {
        out += e.name;
      }
      for (const auto& a : e.args) {
        out += ' ';
        argument(out, a);
      }
      out += ')';
      return;
    case ExprKind::Unary:
      out += e.unary_op == UnaryOp::Negate ? "(neg " : e.unary_op == UnaryOp::Plus ? "(plus " : "(NOT ";
      expr(out, e.operands.at(0));
      out += ')';
      return;
    case ExprKind::Binary:
      out += "(";
      out += binary_op_text(e.binary_op);
      for (const auto& o : e.operands) {
        out += ' ';
        expr(out, o);
      }
      out += ')';
      return;
  }
}

void type(std::string& out, const TypeSpec& t);

void initializer(std::string& out, const Initializer& i) {
  switch (i.kind) {
    case InitKind::None: out += '_'; return;
    case InitKind::Expr: expr(out, i.expr); return;
    case InitKind::Struct:
      out += "(struct-init";
      for (const auto& f : i.fields) {
        out += " (" + f.name + " ";
        initializer(out, f.value);
        out += ')';
      }
      out += ')';
      return;
    case InitKind::Array:
      out += "(array-init";
      for (const auto& el : i.elements) {
        out += ' ';
        if (el.repeat.kind != ExprKind::None) {
          out += "(repeat ";
          expr(out, el.repeat);
          out += ' ';
          initializer(out, el.value);
          out += ')';
        } else {
          initializer(out, el.value);
        }
      }
      out += ')';
      return;
  }
}

void indent_to(std::string& out, int indent) { out.append(static_cast<std::size_t>(indent), ' '); }

void decl(std::string& out, const VarDecl& d, int indent) {
  indent_to(out, indent);
  out += at(d.loc) + " (decl (";
  for (std::size_t k = 0; k < d.names.size(); ++k) out += (k ? " " : "") + d.names[k];
  out += ")";
  if (!d.address.empty()) out += " (at " + d.address + ")";
  out += ' ';
  type(out, d.type);
  if (d.init.kind != InitKind::None) {
    out += " (init ";
    initializer(out, d.init);
    out += ')';
  }
  out += ")\n";
}

void type(std::string& out, const TypeSpec& t) {
  auto range = [&](const Subrange& r) {
    expr(out, r.low);
    out += "..";
    expr(out, r.high);
  };
  switch (t.kind) {
    case TypeKind::Named: out += t.name; return;
    case TypeKind::String:
      out += t.name;
      if (t.length.kind != ExprKind::None) {
        out += '[';
        expr(out, t.length);
        out += ']';
      }
      return;
    case TypeKind::Array:
      out += "(array [";
      for (std::size_t k = 0; k < t.dims.size(); ++k) {
        if (k) out += ", ";
        range(t.dims[k]);
      }
      out += "] ";
      if (!t.element.empty()) type(out, t.element[0]);
      out += ')';
      return;
    case TypeKind::Subrange:
      out += "(subrange " + t.name + " ";
      if (!t.dims.empty()) range(t.dims[0]);
      out += ')';
      return;
    case TypeKind::Enum:
      out += "(enum";
      if (!t.name.empty()) out += " " + t.name;
      for (const auto& e : t.enumerators) {
        out += " (" + e.name;
        if (e.value.kind != ExprKind::None) {
          out += ' ';
          expr(out, e.value);
        }
        out += ')';
      }
      out += ')';
      return;
    case TypeKind::Struct:
      // Members on their own lines would break the one-line type; kept inline.
      out += "(struct";
      for (const auto& m : t.members) {
        std::string member;
        decl(member, m, 0);
        member.pop_back();  // newline
        out += " " + member;
      }
      out += ')';
      return;
  }
}

void statements(std::string& out, const std::vector<Statement>& list, int indent);

void statement(std::string& out, const Statement& s, int indent) {
  indent_to(out, indent);
  out += at(s.loc) + " ";
  switch (s.kind) {
    case StmtKind::Empty: out += "(empty)\n"; return;
    case StmtKind::Exit: out += "(exit)\n"; return;
    case StmtKind::Continue: out += "(continue)\n"; return;
    case StmtKind::Return: out += "(return)\n"; return;
    case StmtKind::Assign:
      out += "(:= ";
      expr(out, s.target);
      out += ' ';
      expr(out, s.value);
      out += ")\n";
      return;
    case StmtKind::Call:
      expr(out, s.value);
      out += '\n';
      return;
    case StmtKind::If:
      out += "(if\n";
      for (const auto& b : s.branches) {
        indent_to(out, indent + 2);
        out += at(b.loc) + " (branch ";
        expr(out, b.condition);
        out += "\n";
        statements(out, b.body, indent + 4);
        indent_to(out, indent + 2);
        out += ")\n";
      }
      break;
    case StmtKind::Case:
      out += "(case ";
      expr(out, s.value);
      out += '\n';
      for (const auto& b : s.cases) {
        indent_to(out, indent + 2);
        out += at(b.loc) + " (labels";
        for (const auto& l : b.labels) {
          out += ' ';
          expr(out, l.low);
          if (l.high.kind != ExprKind::None) {
            out += "..";
            expr(out, l.high);
          }
        }
        out += "\n";
        statements(out, b.body, indent + 4);
        indent_to(out, indent + 2);
        out += ")\n";
      }
      break;
    case StmtKind::For:
      out += "(for ";
      expr(out, s.target);
      out += ' ';
      expr(out, s.value);
      out += ' ';
      expr(out, s.to);
      out += ' ';
      expr(out, s.by);
      out += '\n';
      statements(out, s.body, indent + 2);
      break;
    case StmtKind::While:
      out += "(while ";
      expr(out, s.value);
      out += '\n';
      statements(out, s.body, indent + 2);
      break;
    case StmtKind::Repeat:
      out += "(repeat ";
      expr(out, s.value);
      out += '\n';
      statements(out, s.body, indent + 2);
      break;
  }
  if (s.has_else) {
    indent_to(out, indent + 2);
    out += "(else\n";
    statements(out, s.else_body, indent + 4);
    indent_to(out, indent + 2);
    out += ")\n";
  }
  indent_to(out, indent);
  out += ")\n";
}

void statements(std::string& out, const std::vector<Statement>& list, int indent) {
  for (const auto& s : list) statement(out, s, indent);
}

const char* section_name(VarSectionKind k) {
  switch (k) {
    case VarSectionKind::Var: return "VAR";
    case VarSectionKind::Input: return "VAR_INPUT";
    case VarSectionKind::Output: return "VAR_OUTPUT";
    case VarSectionKind::InOut: return "VAR_IN_OUT";
    case VarSectionKind::Temp: return "VAR_TEMP";
    case VarSectionKind::External: return "VAR_EXTERNAL";
    case VarSectionKind::Global: return "VAR_GLOBAL";
  }
  return "?";
}

void section(std::string& out, const VarSection& s, int indent) {
  indent_to(out, indent);
  out += at(s.loc) + " (" + section_name(s.kind);
  if (s.constant) out += " CONSTANT";
  if (s.retain) out += " RETAIN";
  if (s.non_retain) out += " NON_RETAIN";
  if (s.persistent) out += " PERSISTENT";
  out += '\n';
  for (const auto& d : s.decls) decl(out, d, indent + 2);
  indent_to(out, indent);
  out += ")\n";
}

}  // namespace

std::string dump(const Expr& e) {
  std::string out;
  expr(out, e);
  return out;
}

std::string dump(const TypeSpec& t) {
  std::string out;
  type(out, t);
  return out;
}

std::string dump(const std::vector<Statement>& list, int indent) {
  std::string out;
  statements(out, list, indent);
  return out;
}

std::string dump(const CompilationUnit& unit) {
  std::string out = "(unit\n";
  for (const auto& t : unit.types) {
    out += "  " + at(t.loc) + " (type " + t.name + " ";
    type(out, t.type);
    if (t.init.kind != InitKind::None) {
      out += " (init ";
      initializer(out, t.init);
      out += ')';
    }
    out += ")\n";
  }
  for (const auto& g : unit.globals) section(out, g, 2);
  for (const auto& p : unit.pous) {
    const char* kind = p.kind == PouKind::Function ? "FUNCTION" : p.kind == PouKind::FunctionBlock ? "FUNCTION_BLOCK"
                                                                                                   : "PROGRAM";
    out += "  " + at(p.loc) + " (" + kind + " " + p.name;
    if (!p.return_type.empty()) out += " : " + dump(p.return_type[0]);
    out += '\n';
    if (!p.doc.empty()) out += "    (doc " + quoted(p.doc, '\'') + ")\n";
    for (const auto& s : p.sections) section(out, s, 4);
    out += "    (body\n";
    statements(out, p.body, 6);
    out += "    )\n  )\n";
  }
  return out + ")\n";
}

}  // namespace syncplc::st
