#include "runtime/project/online_change.hpp"

namespace syncplc {

std::size_t carry_over_tags(const Program& from, Program& to) {
  std::size_t n = 0;
  std::vector<bool> touched(to.tasks.size(), false);
  for (const auto& t : to.tags) {
    const Tag* old = from.find_tag(t.name);
    if (!old || old->type != t.type || old->length != t.length) continue;
    std::vector<Cell> v(t.length);
    from.read_tag(*old, v.data());
    auto& img = to.tasks[t.owner]->image;
    std::copy(v.begin(), v.end(), img.begin() + t.cell);
    touched[t.owner] = true;
    ++n;
  }
  // Refill the snapshots so consumers latch the carried values on their first scan.
  for (std::size_t i = 0; i < to.tasks.size(); ++i)
    if (touched[i])
      for (auto& ch : to.tasks[i]->channels) ch->fill(to.tasks[i]->image.data());
  return n;
}

}  // namespace syncplc
