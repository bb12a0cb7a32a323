// The text of a compiled POU (listing.hpp).
#include "runtime/st/vm/listing.hpp"

#include <fmt/format.h>

namespace syncplc::st::vm {

std::string listing(const Module& m, std::uint32_t pou) {
  const CompiledPou& p = m.pous[pou];
  std::string out = fmt::format("{} ({} cells)\n", p.name, p.frame_cells);
  for (std::size_t k = 0; k < p.code.size(); ++k) {
    const Insn& i = p.code[k];
    out += fmt::format("{:5}  {:<16} a={} b={} c={} d={}", k, op_name(i.op), i.a, i.b, i.c, i.d);
    if (k < p.lines.size() && p.lines[k]) out += fmt::format("  (line {})", p.lines[k]);
    out += '\n';
  }
  return out;
}

}  // namespace syncplc::st::vm
