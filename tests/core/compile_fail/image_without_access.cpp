// Must NOT compile (tests/CMakeLists.txt: core.image_access_plain and _made_up, WILL_FAIL):
// a thread that is not the task's (here: what a server or the store would
// write) reaches for a task's process image without an ImageAccess
// (runtime/core/image_access.hpp).
#include "runtime/core/program.hpp"

namespace syncplc {

#ifdef SYNCPLC_CONTROL
// The control case (core.image_access_control, must compile): the same
// line through one of ImageAccess's friends, so that the two failures above
// come from the access rule and not from the set-up.
namespace testing {
class ImageKey {
 public:
  static ImageAccess get() { return ImageAccess{}; }
};
}  // namespace testing
#endif

void server_thread_pokes_an_image(Program& p) {
#if defined(SYNCPLC_CONTROL)
  p.tasks[0]->image(testing::ImageKey::get())[0].raw = 1;
#elif defined(SYNCPLC_WITH_ACCESS_MADE_UP)
  ImageAccess made_up;  // not even so: only the friends can make one
  p.tasks[0]->image(made_up)[0].raw = 1;
#else
  p.tasks[0]->image()[0].raw = 1;
#endif
}

}  // namespace syncplc
