// Date functions (date_fns.hpp).
#include "runtime/st/vm/date_fns.hpp"

#include <chrono>
#include <limits>

namespace syncplc::st::vm {

namespace {

constexpr std::int64_t kNsPerDay = 86'400'000'000'000;
// The days whose midnight 64-bit nanoseconds hold.
constexpr std::int64_t kFirstDay = std::numeric_limits<std::int64_t>::min() / kNsPerDay;
constexpr std::int64_t kLastDay = std::numeric_limits<std::int64_t>::max() / kNsPerDay;

std::int64_t arg(const Cell* args, int k) noexcept { return args[k].get<std::int64_t>(); }

// Days since 1970-01-01 of a valid Gregorian date in DATE's range.
bool day_number(std::int64_t y, std::int64_t m, std::int64_t d, std::int64_t* days) noexcept {
  using namespace std::chrono;
  if (y < 1 || y > 9999 || m < 1 || m > 12 || d < 1 || d > 31) return false;
  const year_month_day ymd{year{static_cast<int>(y)}, month{static_cast<unsigned>(m)}, day{static_cast<unsigned>(d)}};
  if (!ymd.ok()) return false;  // 31 April, 29 February of a common year
  *days = sys_days{ymd}.time_since_epoch().count();
  return *days >= kFirstDay && *days <= kLastDay;
}

bool time_of_day(std::int64_t h, std::int64_t mi, std::int64_t s, std::int64_t ms, std::int64_t* ns) noexcept {
  if (h < 0 || h > 23 || mi < 0 || mi > 59 || s < 0 || s > 59 || ms < 0 || ms > 999) return false;
  *ns = ((h * 60 + mi) * 60 + s) * 1'000'000'000 + ms * 1'000'000;
  return true;
}

}  // namespace

Cell date_fn(DateFn fn, const Cell* args, bool* fault) noexcept {
  Cell out;
  std::int64_t days = 0, tod = 0, ns = 0;
  switch (fn) {
    case DateFn::ConcatDate:
      if (day_number(arg(args, 0), arg(args, 1), arg(args, 2), &days)) out.set<std::int64_t>(days * kNsPerDay);
      else *fault = true;
      break;
    case DateFn::ConcatTod:
      if (time_of_day(arg(args, 0), arg(args, 1), arg(args, 2), arg(args, 3), &tod)) out.set<std::int64_t>(tod);
      else *fault = true;
      break;
    case DateFn::ConcatDt:
      // The last day ends before midnight: DT#2262-04-11-23:47:16.854775807.
      if (day_number(arg(args, 0), arg(args, 1), arg(args, 2), &days) &&
          time_of_day(arg(args, 3), arg(args, 4), arg(args, 5), arg(args, 6), &tod) &&
          !__builtin_add_overflow(days * kNsPerDay, tod, &ns))
        out.set<std::int64_t>(ns);
      else *fault = true;
      break;
    case DateFn::DayOfWeek: {
      const std::int64_t d = arg(args, 0);
      const std::int64_t day = d / kNsPerDay - (d % kNsPerDay < 0 ? 1 : 0);  // floored: a DT's day too
      const std::chrono::weekday w{std::chrono::sys_days{std::chrono::days{day}}};
      out.set<std::int16_t>(static_cast<std::int16_t>(w.c_encoding()));
      break;
    }
  }
  return out;
}

}  // namespace syncplc::st::vm
