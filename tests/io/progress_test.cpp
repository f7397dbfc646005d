#include "scoleid/io/progress.h"

#include <gtest/gtest.h>

#include <stdexcept>
#include <string>
#include <vector>

using namespace scoleid::io;

// Progress printed in pieces reaches a sink as whole lines; an unfinished line when the sink goes;
// one sink at a time.
TEST(Progress, ASinkReceivesWholeLines) {
  std::vector<std::string> lines;
  {
    ProgressSink sink([&](const std::string& l) { lines.push_back(l); });
    progress("%5s", "iter");
    progress(" %13s\n", "cost");
    progress("%d\n%d\n", 1, 2);
    progress("tail");
    EXPECT_THROW(ProgressSink([](const std::string&) {}), std::logic_error);
  }
  EXPECT_EQ(lines, (std::vector<std::string>{" iter          cost", "1", "2", "tail"}));
  // After the sink, a new one may be installed, and it starts afresh.
  std::vector<std::string> again;
  {
    ProgressSink sink([&](const std::string& l) { again.push_back(l); });
    progress("x\n");
  }
  EXPECT_EQ(again, (std::vector<std::string>{"x"}));
}
