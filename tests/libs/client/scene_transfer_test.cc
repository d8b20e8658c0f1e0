// The client library's half of the path-or-bytes rule that needs no Model: what is sent for a
// scene file by content, under which name, and the refusal of a file one message cannot carry.
#include "caliper/client/client.h"  // the umbrella header compiles on its own

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>


namespace caliper::client {
namespace {

namespace fs = std::filesystem;

const std::string kUrdf = std::string(CALIPER_SOURCE_DIR) + "/tests/data/urdf";

TEST(SceneTransfer, NamesWhatIsSent) {
  EXPECT_EQ(SceneFileName("/a/b/arm.dae"), "arm.dae");
  EXPECT_EQ(SceneFileName("/a/b/arm.zae"), "arm.zae");
  EXPECT_EQ(SceneFileName("/a/b/robot.urdf"), "robot.dae");  // sent converted
}

TEST(SceneTransfer, SendsColladaAsItIs) {
  const std::string path = std::string(CALIPER_SOURCE_DIR) + "/models/ecce_arm.dae";
  std::ifstream in(path, std::ios::binary);
  const std::string file((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  ASSERT_FALSE(file.empty());
  EXPECT_EQ(ReadScene(path), file);
}

TEST(SceneTransfer, ConvertsUrdfToCollada) {
  std::vector<std::string> warnings;
  const std::string bytes = ReadScene(kUrdf + "/side.urdf", &warnings);
  EXPECT_NE(bytes.find("<COLLADA"), std::string::npos);
  EXPECT_NE(bytes.find("rod"), std::string::npos) << "the robot's link is missing";
}

TEST(SceneTransfer, RefusesAMissingFileNamingIt) {
  try {
    ReadScene("/nonexistent/scene.dae");
    FAIL() << "no error";
  } catch (const std::exception& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent/scene.dae"), std::string::npos) << e.what();
  }
}

TEST(SceneTransfer, OctetsHoldTheBytes) {
  const std::string bytes("a\0b\xff", 4);
  const auto octets = ToOctets(bytes);
  ASSERT_EQ(octets.length(), 4u);
  EXPECT_EQ(octets[1], 0);
  EXPECT_EQ(octets[3], 0xff);
}

}  // namespace
}  // namespace caliper::client
