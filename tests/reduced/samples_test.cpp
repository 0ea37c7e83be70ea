#include "reduced/samples.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <fstream>

namespace rdyn::reduced {
namespace {

TEST(Samples, CsvRoundTripKeepsEveryBitAndTheRoots) {
  Samples s;
  s.scene = "x";
  s.method = "kinetostatic";
  s.step = 2 * M_PI / 8;
  for (int i = 0; i < 8; ++i) s.q.push_back(i * s.step);
  s.add("m1", {1, 2, 3, 4, 5, 6, 7, 8.123456789012345});
  s.add("m2", {0.1, -0.2, 0.3, -0.4, 0.5, -0.6, 0.7, -1e-300});
  s.roots.emplace_back("m2", std::vector<double>{0.1, 3.3});
  const std::string path = ::testing::TempDir() + "/samples_test.csv";
  write_samples_csv(path, s);
  const Samples r = read_samples_csv(path);
  EXPECT_EQ(r.names, s.names);
  EXPECT_EQ(r.columns, s.columns);
  ASSERT_NE(r.roots_of("m2"), nullptr);
  EXPECT_EQ(*r.roots_of("m2"), s.roots[0].second);
  for (size_t i = 0; i < s.q.size(); ++i) EXPECT_NEAR(r.q[i], s.q[i], 1e-15);
  std::remove(path.c_str());
}

TEST(Samples, MalformedTablesNameFileAndLine) {
  const std::string path = ::testing::TempDir() + "/bad_table.csv";
  std::ofstream(path) << "# rdyn reduced table: scene=x method=k periodic=0 q0=0 step=1\nq_deg,m1\n0,1\n1,abc\n";
  try {
    read_samples_csv(path);
    FAIL();
  } catch (const TableError& e) {
    EXPECT_NE(std::string(e.what()).find("bad_table.csv:4"), std::string::npos) << e.what();
  }
  std::ofstream(path) << "t,q\n1,2\n";
  EXPECT_THROW(read_samples_csv(path), TableError);
  std::remove(path.c_str());
}

}  // namespace
}  // namespace rdyn::reduced
