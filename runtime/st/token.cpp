#include "runtime/st/token.hpp"

#include <utility>

namespace syncplc::st {

namespace {

struct KeywordSpelling {
  std::string_view text;
  TokenKind kind;
};

constexpr KeywordSpelling kKeywords[] = {
    {"FUNCTION", TokenKind::KwFunction}, {"END_FUNCTION", TokenKind::KwEndFunction},
    {"FUNCTION_BLOCK", TokenKind::KwFunctionBlock}, {"END_FUNCTION_BLOCK", TokenKind::KwEndFunctionBlock},
    {"PROGRAM", TokenKind::KwProgram}, {"END_PROGRAM", TokenKind::KwEndProgram},
    {"TYPE", TokenKind::KwType}, {"END_TYPE", TokenKind::KwEndType},
    {"STRUCT", TokenKind::KwStruct}, {"END_STRUCT", TokenKind::KwEndStruct},
    {"ARRAY", TokenKind::KwArray}, {"OF", TokenKind::KwOf},
    {"STRING", TokenKind::KwString}, {"WSTRING", TokenKind::KwWString},
    {"VAR", TokenKind::KwVar}, {"VAR_INPUT", TokenKind::KwVarInput}, {"VAR_OUTPUT", TokenKind::KwVarOutput},
    {"VAR_IN_OUT", TokenKind::KwVarInOut}, {"VAR_TEMP", TokenKind::KwVarTemp},
    {"VAR_EXTERNAL", TokenKind::KwVarExternal}, {"VAR_GLOBAL", TokenKind::KwVarGlobal},
    {"END_VAR", TokenKind::KwEndVar}, {"CONSTANT", TokenKind::KwConstant}, {"RETAIN", TokenKind::KwRetain},
    {"NON_RETAIN", TokenKind::KwNonRetain}, {"PERSISTENT", TokenKind::KwPersistent}, {"AT", TokenKind::KwAt},
    {"IF", TokenKind::KwIf}, {"THEN", TokenKind::KwThen}, {"ELSIF", TokenKind::KwElsif},
    {"ELSE", TokenKind::KwElse}, {"END_IF", TokenKind::KwEndIf}, {"CASE", TokenKind::KwCase},
    {"END_CASE", TokenKind::KwEndCase}, {"FOR", TokenKind::KwFor}, {"TO", TokenKind::KwTo},
    {"BY", TokenKind::KwBy}, {"DO", TokenKind::KwDo}, {"END_FOR", TokenKind::KwEndFor},
    {"WHILE", TokenKind::KwWhile}, {"END_WHILE", TokenKind::KwEndWhile}, {"REPEAT", TokenKind::KwRepeat},
    {"UNTIL", TokenKind::KwUntil}, {"END_REPEAT", TokenKind::KwEndRepeat}, {"EXIT", TokenKind::KwExit},
    {"CONTINUE", TokenKind::KwContinue}, {"RETURN", TokenKind::KwReturn}, {"NOT", TokenKind::KwNot},
    {"AND", TokenKind::KwAnd}, {"OR", TokenKind::KwOr}, {"XOR", TokenKind::KwXor}, {"MOD", TokenKind::KwMod},
    {"TRUE", TokenKind::KwTrue}, {"FALSE", TokenKind::KwFalse},
};

}  // namespace

std::string upper(std::string_view text) {
  std::string out(text);
  for (char& c : out)
    if (c >= 'a' && c <= 'z') c = static_cast<char>(c - 'a' + 'A');
  return out;
}

TokenKind keyword_kind(std::string_view up) {
  if (up.empty()) return TokenKind::Identifier;
  for (const auto& k : kKeywords)
    if (k.text == up) return k.kind;
  return TokenKind::Identifier;
}

bool is_keyword(TokenKind kind) { return kind >= TokenKind::KwFunction && kind <= TokenKind::KwFalse; }

std::string_view describe(TokenKind kind) {
  for (const auto& k : kKeywords)
    if (k.kind == kind && !k.text.empty()) return k.text;
  switch (kind) {
    case TokenKind::End: return "end of file";
    case TokenKind::Identifier: return "a name";
    case TokenKind::Integer: return "an integer literal";
    case TokenKind::Real: return "a REAL literal";
    case TokenKind::Duration: return "a duration literal";
    case TokenKind::Date: return "a DATE literal";
    case TokenKind::TimeOfDay: return "a TOD literal";
    case TokenKind::DateAndTime: return "a DT literal";
    case TokenKind::String: return "a string literal";
    case TokenKind::WString: return "a WSTRING literal";
    case TokenKind::DirectAddress: return "a direct address";
    case TokenKind::Pragma: return "a pragma";
    case TokenKind::LParen: return "'('";
    case TokenKind::RParen: return "')'";
    case TokenKind::LBracket: return "'['";
    case TokenKind::RBracket: return "']'";
    case TokenKind::Comma: return "','";
    case TokenKind::Semicolon: return "';'";
    case TokenKind::Colon: return "':'";
    case TokenKind::Assign: return "':='";
    case TokenKind::OutputAssign: return "'=>'";
    case TokenKind::Dot: return "'.'";
    case TokenKind::DotDot: return "'..'";
    case TokenKind::Hash: return "'#'";
    case TokenKind::Plus: return "'+'";
    case TokenKind::Minus: return "'-'";
    case TokenKind::Star: return "'*'";
    case TokenKind::Slash: return "'/'";
    case TokenKind::Power: return "'**'";
    case TokenKind::Ampersand: return "'&'";
    case TokenKind::Equal: return "'='";
    case TokenKind::NotEqual: return "'<>'";
    case TokenKind::Less: return "'<'";
    case TokenKind::LessEqual: return "'<='";
    case TokenKind::Greater: return "'>'";
    case TokenKind::GreaterEqual: return "'>='";
    case TokenKind::Caret: return "'^'";
    case TokenKind::Error: return "a bad token";
    default: return "a token";
  }
}

std::string describe(const Token& token) {
  switch (token.kind) {
    case TokenKind::Identifier: return "name '" + token.text + "'";
    case TokenKind::End: return "end of file";
    case TokenKind::Integer:
    case TokenKind::Real:
    case TokenKind::Duration:
    case TokenKind::Date:
    case TokenKind::TimeOfDay:
    case TokenKind::DateAndTime:
    case TokenKind::String:
    case TokenKind::WString:
    case TokenKind::DirectAddress:
      return std::string(describe(token.kind)) + " " + (token.text.size() > 40 ? token.text.substr(0, 40) + "…" : token.text);
    default:
      if (is_keyword(token.kind)) return upper(token.text);
      return std::string(describe(token.kind));
  }
}

}  // namespace syncplc::st
