// What a reader of the HTTP API may see (runtime/web/read_access.hpp): the
// cells of hmi: none tags and of the pins wired to them, in the task that
// owns them and in the tasks that read them; paths cut to their file names.
#include <gtest/gtest.h>

#include "runtime/project/loader.hpp"
#include "runtime/web/read_access.hpp"
#include "tests/support/test_blocks.hpp"

namespace syncplc::web {
namespace read_access {

const char* kProject = R"(project: {name: hidden}
tasks:
  - {name: fast, period: 1ms}
  - {name: slow, period: 10ms}
tags:
  - {name: sw, type: BOOL, init: TRUE}
  - {name: shown, type: BOOL, hmi: read}
  - {name: secret, type: INT}
  - {name: relay, type: INT, hmi: read}
blocks:
  - {name: gate, type: MOVE, task: fast}
  - {name: k, type: MOVE, task: fast, inputs: {IN: 7}}
  - {name: reader, type: MOVE, task: slow}
  - {name: other, type: MOVE, task: slow, inputs: {IN: 1}}
connections:
  - sw -> gate.IN
  - gate.OUT -> shown
  - k.OUT -> secret
  - secret -> reader.IN
  - reader.OUT -> relay
)";

// Whether `ref` of `p` is hidden (it must resolve).
bool hides(const Program& p, const HiddenCells& hidden, const char* ref) {
  auto c = p.resolve(ref);
  EXPECT_TRUE(c) << ref;
  return c && hidden.hides(*c);
}

std::string first_error(const LoadResult& r) {
  return r.diagnostics.sorted().empty() ? "" : r.diagnostics.sorted().front().text();
}

TEST(ReadAccess, HmiNoneTagsAndThePinsWiredToThemAreHiddenInEveryTask) {
  const LoadResult r = load_project(syncplc::testing::write_temp_file("hidden.yaml", kProject), {});
  ASSERT_TRUE(r.ok()) << first_error(r);
  const Program& p = *r.program;
  const HiddenCells hidden(p);
  auto hides = [&](const char* ref) { return read_access::hides(p, hidden, ref); };
  for (const char* ref : {"sw", "secret", "gate.IN", "k.OUT", "reader.IN"}) EXPECT_TRUE(hides(ref)) << ref;
  // What the project chose to show, and what no hidden tag feeds.
  for (const char* ref : {"shown", "relay", "gate.OUT", "reader.OUT", "k.IN", "other.IN", "other.OUT"})
    EXPECT_FALSE(hides(ref)) << ref;
  EXPECT_FALSE(sees_everything(std::nullopt));
  EXPECT_FALSE(sees_everything(Session{"olga", Role::Operator}));
  EXPECT_TRUE(sees_everything(Session{"erik", Role::Engineer}));
}

// An ST FUNCTION_BLOCK holds each input and output twice, in its pin and in
// its variables: a hidden tag wired to the pin hides both, so neither
// instance.x (the variable of an output) nor the variables list shows it.
TEST(ReadAccess, AnStInstancesInputsAndOutputsAreHiddenInItsVariablesToo) {
  syncplc::testing::write_temp_file("st_hidden_twice.st", R"(FUNCTION_BLOCK Twice
VAR_INPUT x : LREAL; END_VAR
VAR_OUTPUT y : LREAL; END_VAR
VAR last : LREAL; END_VAR
y := 2.0 * x;
last := x;
END_FUNCTION_BLOCK
)");
  const LoadResult r = load_project(syncplc::testing::write_temp_file("st_hidden.yaml", R"(project: {name: st_hidden}
tasks: [{name: main, period: 1ms}]
sources: [st_hidden_twice.st]
tags:
  - {name: secret_in, type: LREAL, init: 1.234}
  - {name: secret_out, type: LREAL}
  - {name: open_in, type: LREAL, hmi: read}
blocks:
  - {name: tw, type: Twice}
  - {name: pub, type: Twice}
connections:
  - secret_in -> tw.x
  - tw.y -> secret_out
  - open_in -> pub.x
)"), {});
  ASSERT_TRUE(r.ok()) << first_error(r);
  const Program& p = *r.program;
  const HiddenCells hidden(p);
  auto hides = [&](const char* ref) { return read_access::hides(p, hidden, ref); };
  for (const char* ref : {"tw.x", "tw.y"}) EXPECT_TRUE(hides(ref)) << ref;
  for (const char* ref : {"pub.x", "pub.y"}) EXPECT_FALSE(hides(ref)) << ref;
  // The variables list shows what is not a pin ("last"), once.
  for (const auto& b : p.block_instances())
    if (b.name == "tw") {
      ASSERT_EQ(b.variables.size(), 1u);
      EXPECT_EQ(b.variables[0].name, "last");
    }
}

TEST(ReadAccess, PathsAreCutToTheirFileName) {
  EXPECT_EQ(without_dirs("/srv/plc/line.yaml:3:4: unknown block"), "line.yaml:3:4: unknown block");
  EXPECT_EQ(without_dirs("started project /home/eng/p/line.yaml, database /var/lib/plc/plc.db"),
            "started project line.yaml, database plc.db");
  EXPECT_EQ(without_dirs("reloaded version 3 (/root/.local/state/syncplc/projects/ab12/x.yaml): 2 kept"),
            "reloaded version 3 (x.yaml): 2 kept");
  EXPECT_EQ(without_dirs("speed := 1.5 m/s (by olga)"), "speed := 1.5 m/s (by olga)") << "a unit is no path";
  nlohmann::json runtime{{"project_file", "/srv/plc/line.yaml"}, {"store", {{"state", "ok"}, {"detail", "/srv/plc/plc.db"}}}};
  hide_paths(runtime);
  EXPECT_FALSE(runtime.contains("project_file"));
  EXPECT_EQ(runtime["store"]["detail"], "plc.db");
}

}  // namespace read_access
}  // namespace syncplc::web
