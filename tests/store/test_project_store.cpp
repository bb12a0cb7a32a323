// The project store: every load kept with all its files (includes too),
// identical contents stored once, rejected loads with their errors, versions
// in order, the content hash as documented (checked with sha256sum), a
// version extracted again, and the job that writes loads on the store thread.
#include <gtest/gtest.h>

#include <SQLiteCpp/Statement.h>

#include <cstdio>
#include <filesystem>
#include <fstream>

#include "runtime/project/loader.hpp"
#include "runtime/store/database.hpp"
#include "runtime/store/project_store.hpp"
#include "runtime/store/projects_job.hpp"
#include "runtime/store/store_thread.hpp"
#include "tests/store/store_test_util.hpp"

namespace syncplc::store {
namespace {

namespace fs = std::filesystem;

void write(const fs::path& p, const std::string& text) {
  fs::create_directories(p.parent_path());
  std::ofstream(p, std::ios::binary) << text;
}

std::unique_ptr<Database> open_project_db(const std::string& dir) {
  OpenReport report;
  std::string err;
  auto db = Database::open(dir + "/plc.db", &report, &err);
  EXPECT_TRUE(db) << err;
  EXPECT_TRUE(prepare_projects(db->sql(), &err)) << err;
  return db;
}

int count(SQLite::Database& db, const std::string& table) {
  SQLite::Statement q(db, "SELECT count(*) FROM " + table);
  q.executeStep();
  return q.getColumn(0).getInt();
}

ProjectLoad load_of(const LoadResult& r, const std::string& origin) {
  ProjectLoad l;
  l.origin = origin;
  l.source = "test";
  l.time_ns = 1'700'000'000'000'000'000;
  l.accepted = r.ok();
  if (r.program) l.project_name = r.program->name, l.project_version = r.program->version;
  for (const auto& d : r.diagnostics.sorted()) l.errors.push_back(d.text());
  l.content = make_content(r.sources);
  return l;
}

// A project in main/ that includes ../common/tags.yaml, which includes more.yaml beside it.
std::string write_project(const std::string& dir, const std::string& block_type = "MOVE") {
  write(dir + "/common/tags.yaml", "include: more.yaml\ntags:\n  - {name: a, type: LREAL, init: 2}\n");
  write(dir + "/common/more.yaml", "tags:\n  - {name: b, type: LREAL}\n");
  const std::string main = dir + "/main/line.yaml";
  write(main, "project: {name: line, version: '1.2'}\ninclude: ../common/tags.yaml\ntasks: [{name: t, period: 1ms}]\n"
              "blocks: [{name: m, type: " + block_type + "}]\nconnections: [a -> m.IN, m.OUT -> b]\n");
  return main;
}

TEST(ProjectStore, KeepsTheProjectFileAndEveryIncludeNamedFromTheirCommonDirectory) {
  const std::string dir = testing::fresh_dir("includes");
  auto r = load_project(write_project(dir));
  ASSERT_TRUE(r.ok());
  const ProjectContent c = make_content(r.sources);
  ASSERT_EQ(c.files.size(), 3u);
  EXPECT_EQ(c.files[0].path, "main/line.yaml");  // the project file first, then by name
  EXPECT_EQ(c.files[1].path, "common/more.yaml");
  EXPECT_EQ(c.files[2].path, "common/tags.yaml");
  EXPECT_EQ(c.files[1].text, "tags:\n  - {name: b, type: LREAL}\n");
  EXPECT_EQ(c.hash.size(), 64u);
}

TEST(ProjectStore, TheContentHashIsTheDocumentedSha256) {
  const std::string dir = testing::fresh_dir("hash");
  auto r = load_project(write_project(dir));
  const ProjectContent c = make_content(r.sources);
  // The documented encoding, hashed by coreutils' sha256sum.
  std::string encoded;
  for (const auto& f : c.files) encoded += f.path + '\0' + std::to_string(f.text.size()) + '\0' + f.text;
  write(dir + "/encoded", encoded);
  FILE* p = popen(("sha256sum " + dir + "/encoded").c_str(), "r");
  ASSERT_TRUE(p);
  char out[65] = {};
  ASSERT_EQ(fread(out, 1, 64, p), 64u);
  pclose(p);
  EXPECT_EQ(c.hash, std::string(out));
}

TEST(ProjectStore, IdenticalFilesAreStoredOnceAndEachLoadIsItsOwnVersion) {
  const std::string dir = testing::fresh_dir("dedupe");
  auto db = open_project_db(dir);
  const std::string main = write_project(dir);
  auto r = load_project(main);
  EXPECT_EQ(record_load(db->sql(), load_of(r, "run")), 1);
  EXPECT_EQ(record_load(db->sql(), load_of(load_project(main), "reload")), 2);
  EXPECT_EQ(count(db->sql(), "project_content"), 1);
  EXPECT_EQ(count(db->sql(), "project_files"), 3);
  write(dir + "/common/more.yaml", "tags:\n  - {name: b, type: LREAL, init: 1}\n");  // one include changes
  EXPECT_EQ(record_load(db->sql(), load_of(load_project(main), "reload")), 3);
  EXPECT_EQ(count(db->sql(), "project_content"), 2);
  EXPECT_EQ(count(db->sql(), "project_files"), 6);
  const auto v = list_versions(db->sql());
  ASSERT_EQ(v.size(), 3u);
  EXPECT_EQ(v[0].hash, v[1].hash);
  EXPECT_NE(v[1].hash, v[2].hash);
  EXPECT_EQ(v[2].files, 3);
  EXPECT_EQ(v[1].origin, "reload");
  EXPECT_EQ(v[0].project_name, "line");
  EXPECT_EQ(v[0].project_version, "1.2");
  EXPECT_EQ(version_files(db->sql(), 3)[1].text, "tags:\n  - {name: b, type: LREAL, init: 1}\n");
  EXPECT_EQ(version_files(db->sql(), 1)[1].text, "tags:\n  - {name: b, type: LREAL}\n");
}

TEST(ProjectStore, ARejectedLoadKeepsItsFilesAndErrorsAndIsNeverTheLastAccepted) {
  const std::string dir = testing::fresh_dir("rejected");
  auto db = open_project_db(dir);
  const std::string good = write_project(dir + "/good");
  record_load(db->sql(), load_of(load_project(good), "run"));
  auto bad = load_project(write_project(dir + "/bad", "NOPE"));
  ASSERT_FALSE(bad.ok());
  EXPECT_EQ(record_load(db->sql(), load_of(bad, "reload")), 2);
  auto v = find_version(db->sql(), 2);
  ASSERT_TRUE(v);
  EXPECT_FALSE(v->accepted);
  EXPECT_EQ(v->files, 3);
  ASSERT_EQ(v->errors.size(), bad.diagnostics.size());
  EXPECT_NE(v->errors[0].find("unknown block type 'NOPE'"), std::string::npos) << v->errors[0];
  auto last = last_accepted(db->sql());
  ASSERT_TRUE(last);
  EXPECT_EQ(last->number, 1);
  EXPECT_TRUE(same_as_last_accepted(db->sql(), make_content(load_project(good).sources).hash));
  EXPECT_FALSE(same_as_last_accepted(db->sql(), v->hash));
}

TEST(ProjectStore, AProjectFileThatCannotBeReadIsARejectedVersionWithoutFiles) {
  const std::string dir = testing::fresh_dir("missing");
  auto db = open_project_db(dir);
  auto r = load_project(dir + "/nothing.yaml");
  ASSERT_FALSE(r.ok());
  EXPECT_TRUE(r.sources.empty());
  record_load(db->sql(), load_of(r, "run"));
  auto v = find_version(db->sql(), 1);
  ASSERT_TRUE(v);
  EXPECT_EQ(v->hash, "");
  EXPECT_EQ(v->files, 0);
  EXPECT_NE(v->errors.at(0).find("cannot open file"), std::string::npos);
  EXPECT_FALSE(last_accepted(db->sql()));
  EXPECT_FALSE(same_as_last_accepted(db->sql(), ""));
}

TEST(ProjectStore, ALoadWithAMissingIncludeKeepsTheFilesItRead) {
  const std::string dir = testing::fresh_dir("missing_include");
  write(dir + "/p.yaml", "include: [a.yaml, gone.yaml]\ntasks: [{name: t, period: 1ms}]\n");
  write(dir + "/a.yaml", "tags: [{name: x, type: BOOL}]\n");
  auto r = load_project(dir + "/p.yaml");
  ASSERT_FALSE(r.ok());
  const ProjectContent c = make_content(r.sources);
  ASSERT_EQ(c.files.size(), 2u);
  EXPECT_EQ(c.files[0].path, "p.yaml");
  EXPECT_EQ(c.files[1].path, "a.yaml");
}

TEST(ProjectStore, AnExtractedVersionLoadsAsTheOriginalDid) {
  const std::string dir = testing::fresh_dir("extract");
  auto db = open_project_db(dir);
  record_load(db->sql(), load_of(load_project(write_project(dir + "/src")), "run"));
  std::string err;
  const std::string main = extract_files(version_files(db->sql(), 1), dir + "/out", &err);
  ASSERT_EQ(main, dir + "/out/main/line.yaml") << err;
  EXPECT_EQ(fs::status(dir + "/out").permissions() & fs::perms::all, fs::perms::owner_all);
  auto again = load_project(main);
  ASSERT_TRUE(again.ok());
  EXPECT_EQ(make_content(again.sources).hash, find_version(db->sql(), 1)->hash);
}

TEST(ProjectStore, ExtractingRefusesANameThatLeavesItsDirectory) {
  const std::string dir = testing::fresh_dir("escape");
  std::string err;
  EXPECT_EQ(extract_files({{"../evil.yaml", "x"}}, dir + "/out", &err), "");
  EXPECT_NE(err.find("would leave"), std::string::npos) << err;
  EXPECT_FALSE(fs::exists(dir + "/evil.yaml"));
}

TEST(ProjectStore, TheJobWritesSubmittedLoadsInOrderOnTheStoreThread) {
  const std::string dir = testing::fresh_dir("job");
  OpenReport report;
  std::string err;
  auto thread = std::make_unique<StoreThread>(Database::open(dir + "/plc.db", &report, &err));
  auto job = std::make_unique<ProjectsJob>();
  ProjectsJob& j = *job;
  ASSERT_TRUE(thread->add(std::move(job), &err)) << err;
  const std::string main = write_project(dir);
  j.submit(load_of(load_project(main), "run"));
  thread->start();
  j.submit(load_of(load_project(main), "reload"));
  thread->wake();
  thread->stop();  // the final run writes what is left
  auto v = list_versions(thread->database().sql());
  ASSERT_EQ(v.size(), 2u);
  EXPECT_EQ(v[0].origin, "run");
  EXPECT_EQ(v[1].origin, "reload");
  EXPECT_EQ(j.dropped(), 0u);
  EXPECT_EQ(j.due_ns(), std::numeric_limits<std::int64_t>::max());
}

}  // namespace
}  // namespace syncplc::store
