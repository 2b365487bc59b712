// The core must stay ROS-free: this test reads every source file under src/ and fails
// naming the file and line of any ROS include.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <regex>
#include <string>
#include <vector>

namespace fs = std::filesystem;

TEST(NoRosHeaders, CoreSourcesIncludeNoRosHeader) {
  const std::regex ros_include(
      R"(^\s*#\s*include\s*[<"](ros|rosbag|tf2_ros|tf2_msgs|std_msgs|geometry_msgs|sensor_msgs|visualization_msgs|palcas_msgs|roscpp|rospy|xmlrpcpp|actionlib)/)");
  std::vector<std::string> offenders;
  int files_read = 0;
  for (const auto& entry : fs::recursive_directory_iterator(PALCAS_CORE_SOURCE_DIR)) {
    const auto ext = entry.path().extension().string();
    if (ext != ".h" && ext != ".hpp" && ext != ".cpp" && ext != ".cc") continue;
    std::ifstream in(entry.path());
    std::string line;
    int number = 0;
    ++files_read;
    while (std::getline(in, line)) {
      ++number;
      if (std::regex_search(line, ros_include))
        offenders.push_back(entry.path().string() + ":" + std::to_string(number) + ": " + line);
    }
  }
  EXPECT_GT(files_read, 3) << "the scan found almost no sources; is the path right?";
  for (const auto& o : offenders) ADD_FAILURE() << "ROS header in the core: " << o;
}

TEST(NoRosHeaders, DetectorRecognisesRosIncludes) {
  const std::regex ros_include(R"(^\s*#\s*include\s*[<"](ros|std_msgs|palcas_msgs)/)");
  EXPECT_TRUE(std::regex_search("#include <ros/ros.h>", ros_include));
  EXPECT_TRUE(std::regex_search("  #include \"palcas_msgs/Advisory.h\"", ros_include));
  EXPECT_FALSE(std::regex_search("#include <Eigen/Dense>", ros_include));
  EXPECT_FALSE(std::regex_search("#include \"palcas_core/common/action.h\"", ros_include));
}
