// A project sent over HTTP is untrusted input: names that stay inside it,
// limits, errors named by the uploaded file names, nothing read outside.
#include <gtest/gtest.h>
#include <stdlib.h>

#include <filesystem>

#include "runtime/web/project_upload.hpp"

namespace syncplc::web {
namespace {

namespace fs = std::filesystem;

const char* kGood = R"(project: {name: up, version: 1.0.0}
tasks:
  - {name: main, period: 10ms}
include: [tags.yaml]
)";
const char* kTags = R"(tags:
  - {name: speed, type: LREAL, hmi: readwrite}
)";

struct TempRoot {
  std::string dir;
  TempRoot() {
    std::string t = (fs::temp_directory_path() / "upload-test-XXXXXX").string();
    dir = mkdtemp(t.data());
  }
  ~TempRoot() { fs::remove_all(dir); }
};

std::optional<Upload> parse(const nlohmann::json& j, std::string* why) { return parse_upload(j, 8, why); }

TEST(ProjectUpload, AGoodProjectWithAnIncludeChecksAndLeavesNothing) {
  TempRoot root;
  std::string why;
  auto u = parse({{"main", "main.yaml"}, {"files", {{"tags.yaml", kTags}, {"main.yaml", kGood}}}}, &why);
  ASSERT_TRUE(u) << why;
  EXPECT_EQ(u->files.front().path, "main.yaml");  // the main file first
  const UploadCheck c = check_upload(*u, root.dir, {});
  EXPECT_TRUE(c.ok) << c.errors.dump();
  EXPECT_EQ(c.hash.size(), 64u);
  EXPECT_TRUE(fs::is_empty(root.dir));  // the check's directory is gone
}

TEST(ProjectUpload, ErrorsAreNamedByTheUploadedFileAndLine) {
  TempRoot root;
  std::string why;
  std::string bad = kTags;
  bad += "  - {name: level, type: LREEL}\n";
  auto u = parse({{"main", "main.yaml"}, {"files", {{"tags.yaml", bad}, {"main.yaml", kGood}}}}, &why);
  ASSERT_TRUE(u) << why;
  const UploadCheck c = check_upload(*u, root.dir, {});
  ASSERT_FALSE(c.ok);
  ASSERT_EQ(c.errors.size(), 1u) << c.errors.dump();
  EXPECT_EQ(c.errors[0]["where"], "tags.yaml:3:25") << c.errors.dump();
  EXPECT_NE(c.errors[0]["message"].get<std::string>().find("LREEL"), std::string::npos);
  EXPECT_EQ(c.errors.dump().find(root.dir), std::string::npos);  // no server path in the answer
}

TEST(ProjectUpload, AnIncludeOutsideTheUploadIsRefused) {
  TempRoot root;
  const std::string outside = root.dir + "/../outside-" + std::to_string(getpid()) + ".yaml";
  {
    std::FILE* f = std::fopen(outside.c_str(), "w");
    std::fputs(kTags, f);
    std::fclose(f);
  }
  std::string main = kGood;
  main.replace(main.find("[tags.yaml]"), 11, "[../../" + fs::path(outside).filename().string() + "]");
  std::string why;
  auto u = parse({{"main", "main.yaml"}, {"files", {{"main.yaml", main}}}}, &why);
  ASSERT_TRUE(u) << why;
  const UploadCheck c = check_upload(*u, root.dir, {});
  fs::remove(outside);
  ASSERT_FALSE(c.ok);
  // Refused before the loader opens it, at the include's place.
  ASSERT_EQ(c.errors.size(), 1u) << c.errors.dump();
  EXPECT_EQ(c.errors[0]["where"], "main.yaml:4:11") << c.errors.dump();
  EXPECT_NE(c.errors[0]["message"].get<std::string>().find("not among the files sent"), std::string::npos);
  // An absolute include and one the loader would block on are refused the same way.
  for (const char* target : {"/dev/zero", "/etc/passwd"}) {
    std::string m = kGood;
    m.replace(m.find("[tags.yaml]"), 11, std::string("[") + target + "]");
    auto v = parse({{"main", "main.yaml"}, {"files", {{"main.yaml", m}}}}, &why);
    ASSERT_TRUE(v) << why;
    const UploadCheck d = check_upload(*v, root.dir, {});
    ASSERT_FALSE(d.ok) << target;
    EXPECT_NE(d.errors.dump().find("not among the files sent"), std::string::npos) << d.errors.dump();
  }
}

TEST(ProjectUpload, HostileNamesAndShapesAreRefused) {
  std::string why;
  for (const char* name : {"../x.yaml", "/etc/x.yaml", "a/../../x.yaml", "a\\b.yaml", "x.sh", "./x.yaml", "a//b.yaml", ""}) {
    EXPECT_FALSE(parse({{"main", name}, {"files", {{name, kGood}}}}, &why)) << name;
    EXPECT_FALSE(why.empty());
  }
  EXPECT_FALSE(parse({{"main", "a.yaml"}, {"files", {{"b.yaml", kGood}}}}, &why));
  EXPECT_NE(why.find("'a.yaml' is not among"), std::string::npos) << why;
  EXPECT_FALSE(parse({{"main", "a.yaml"}, {"files", {{"a.yaml", 12}}}}, &why));
  EXPECT_FALSE(parse({{"files", {{"a.yaml", kGood}}}}, &why));
  nlohmann::json many = nlohmann::json::object();
  for (int i = 0; i < 9; ++i) many["f" + std::to_string(i) + ".yaml"] = "x: 1";
  EXPECT_FALSE(parse({{"main", "f0.yaml"}, {"files", many}}, &why));
  EXPECT_NE(why.find("at most 8"), std::string::npos) << why;
}

TEST(ProjectUpload, ErrorLinesSplitIntoWhereAndMessage) {
  EXPECT_EQ(error_json("/x/up/a.yaml:12:7: period: bad", "/x/up"),
            (nlohmann::json{{"where", "a.yaml:12:7"}, {"message", "period: bad"}}));
  EXPECT_EQ(error_json("driver io: cannot open", "/x/up")["message"], "driver io: cannot open");
  EXPECT_TRUE(error_json("driver io: cannot open", "/x/up")["where"].is_null());
}

}  // namespace
}  // namespace syncplc::web
