#include "uh/haptico/trace_csv_writer.hpp"

#include <gtest/gtest.h>

#include <chrono>
#include <cstdio>
#include <fstream>
#include <string>
#include <thread>

#include "uh/haptico/haptic_manager.hpp"
#include "uh/haptico/sim_line_device.hpp"

namespace uh::haptico {
namespace {

TEST(TraceCsvWriter, WritesEveryTickOfAThreadedRun) {
  const std::string path = testing::TempDir() + "uh_trace_writer_test.csv";
  HapticManager manager(std::make_unique<SimLineDevice>(SimLineOptions{}), {.trace_capacity = 4096});
  manager.force_on_haptic_tick().add_delegate([](const DeviceState&, DeviceCommand& cmd) { cmd.force = {0, 0, 1}; });
  std::ofstream(path) << "an earlier trace\n";
  auto writer = TraceCsvWriter::start(manager, path, {.drain_period_s = 0.01});
  ASSERT_TRUE(writer) << writer.error().message;
  ASSERT_TRUE(manager.start());
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(10);
  while (manager.stats().ticks < 100 && std::chrono::steady_clock::now() < deadline) {
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  manager.stop();
  {
    // the earlier file stays whole until the new trace is complete
    std::ifstream before(path);
    std::string first;
    std::getline(before, first);
    EXPECT_EQ(first, "an earlier trace");
  }
  ASSERT_TRUE((*writer)->stop());
  const HapticStats stats = manager.stats();
  EXPECT_EQ(stats.trace_dropped, 0u);
  // every tick, then the zero the haptic thread sent as it ended
  EXPECT_EQ((*writer)->rows_written(), stats.ticks + 1);

  std::ifstream in(path);
  std::string line;
  std::getline(in, line);
  EXPECT_EQ(line.rfind("tick_time_s,device_time_s,", 0), 0u);
  std::uint64_t rows = 0;
  std::string last;
  while (std::getline(in, line)) {
    ++rows;
    last = line;
  }
  EXPECT_EQ(rows, stats.ticks + 1);
  EXPECT_NE(last.find(",0,0,0,0,0,0,0,0,0,0,0,0,1024"), std::string::npos)
      << "requested and sent zero, flags kTraceStopped: " << last;
  EXPECT_GT(rows, 10u);
  std::remove(path.c_str());
}

TEST(TraceCsvWriter, RefusesManagerWithoutTraceAndUnwritablePath) {
  HapticManager no_trace(std::make_unique<SimLineDevice>(SimLineOptions{}));
  EXPECT_EQ(TraceCsvWriter::start(no_trace, "x.csv").error().message,
            "trace writer: the haptic manager records no trace (set HapticManagerOptions::trace_capacity)");
  HapticManager manager(std::make_unique<SimLineDevice>(SimLineOptions{}), {.trace_capacity = 16});
  EXPECT_EQ(TraceCsvWriter::start(manager, "/nonexistent/dir/t.csv").error().message,
            "/nonexistent/dir/t.csv: cannot create a file in /nonexistent/dir: No such file or directory");
}

}  // namespace
}  // namespace uh::haptico
