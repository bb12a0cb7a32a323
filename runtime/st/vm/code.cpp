// Names of the operations (for listings and tests), the module's POU lookup
// and the process-wide texts of fault events.
#include "runtime/st/vm/code.hpp"

#include <mutex>
#include <set>

namespace syncplc::st::vm {

std::string_view op_name(Op op) {
  static constexpr std::string_view names[] = {
#define X(op) #op,
      SYNCPLC_ST_OPS(X)
#undef X
  };
  const auto i = static_cast<std::size_t>(op);
  return i < std::size(names) ? names[i] : "?";
}

int Module::find(std::string_view pou) const {
  for (std::size_t i = 0; i < pous.size(); ++i)
    if (same_name(pous[i].name, pou)) return static_cast<int>(i);
  return -1;
}

// Interned: an event's text must outlive the module that raised it (the
// event logger may read it after an online change replaced the module), and
// reloading the same source reuses the same texts, so the set stays bounded
// by the distinct fault sites ever loaded. Load path only (takes a lock).
const char* fault_text(const std::string& text) {
  static std::mutex mutex;
  static std::set<std::string> texts;
  std::lock_guard lock(mutex);
  return texts.insert(text).first->c_str();
}

}  // namespace syncplc::st::vm
