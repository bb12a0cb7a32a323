// The capability to touch a task's process image (issue 21: "the compiler,
// not a comment, stops a non-real-time thread from touching an image").
//
// Task::image() takes an ImageAccess, and only these can make one:
//   - the task itself (its scan, publish and account run on its thread);
//   - an online change's switch (TaskHandover::perform, mirroring: on the
//     old task's thread) and its plan (a new program no thread runs yet);
//   - the virtual clock, whose one thread is every task's thread: it hands
//     keys to virtual-time tools (scan-cycle tests, traces, metrics);
//   - the loader's build and the restore of retained values, before any
//     thread runs the program;
//   - the tests' single-threaded fixtures.
// Every other thread (the Modbus and HTTP servers, the store's jobs, the
// supervisor, the command line) reads through the narrow interface:
// snapshots (Program::read_tag), queues (write_tag, force), pin monitors
// (read_value) and the transaction; a call to Task::image() there does not
// compile.
#pragma once

namespace syncplc {

class Task;
struct TaskHandover;
class VirtualClock;
class ProgramBuilder;
class ChangePlanner;
namespace store {
class RetainRestore;
}
namespace testing {
class ImageKey;
}

class ImageAccess {
 private:
  constexpr ImageAccess() = default;
  friend class Task;
  friend struct TaskHandover;
  friend class VirtualClock;
  friend class ProgramBuilder;
  friend class ChangePlanner;
  friend class store::RetainRestore;
  friend class testing::ImageKey;
};

}  // namespace syncplc
