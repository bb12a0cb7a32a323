// Where `syncplc run` finds the HMI without --hmi-dir (runtime/web/hmi_location.hpp):
// the copy installed beside the executable when it is there, else the build's.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>

#include "runtime/web/hmi_location.hpp"

namespace syncplc::web {
namespace test_hmi_location {

namespace fs = std::filesystem;

class HmiLocation : public ::testing::Test {
 protected:
  void SetUp() override {
    root_ = fs::temp_directory_path() / ("syncplc-hmi-location-" + std::to_string(::getpid()));
    fs::remove_all(root_);
    fs::create_directories(root_ / "usr/bin");
    std::ofstream(root_ / "usr/bin/syncplc") << "";
  }
  void TearDown() override { fs::remove_all(root_); }
  fs::path root_;
};

TEST_F(HmiLocation, TheBuildsCopyWhenNothingIsInstalledBesideTheBinary) {
  EXPECT_EQ(hmi_dir_for(root_ / "usr/bin/syncplc", "../share/syncplc/hmi", "/src/hmi_web/dist"), "/src/hmi_web/dist");
}

TEST_F(HmiLocation, TheInstalledCopyWhenItHasAnIndex) {
  fs::create_directories(root_ / "usr/share/syncplc/hmi");
  // A directory without index.html is not an HMI (an install that failed half-way).
  EXPECT_EQ(hmi_dir_for(root_ / "usr/bin/syncplc", "../share/syncplc/hmi", "/src/hmi_web/dist"), "/src/hmi_web/dist");
  std::ofstream(root_ / "usr/share/syncplc/hmi/index.html") << "<html></html>";
  EXPECT_EQ(hmi_dir_for(root_ / "usr/bin/syncplc", "../share/syncplc/hmi", "/src/hmi_web/dist"),
            (root_ / "usr/share/syncplc/hmi").string());
}

TEST_F(HmiLocation, NoExecutablePathFallsBackToTheBuild) {
  EXPECT_EQ(hmi_dir_for(fs::path(), "../share/syncplc/hmi", "/src/hmi_web/dist"), "/src/hmi_web/dist");
}

TEST(HmiLocationDefault, ATestBinaryInTheBuildTreeServesTheBuildsCopy) {
  // The test executable is in the build tree, where nothing is installed beside it.
  EXPECT_EQ(default_hmi_dir(), SYNCPLC_TEST_HMI_DIST);
}

}  // namespace test_hmi_location
}  // namespace syncplc::web
