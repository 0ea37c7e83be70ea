// timeseries.csv (validate/report/timeseries_csv.cpp): the header names t,q,qdot,qddot,energy,work,
// then F_<force> per constraint force, then the joint-output columns; every value after t reads
// back bit for bit (17 significant digits), t to its 10 written digits; a non-finite value is a
// NumericalError naming what and when, and inside the command's output folder nothing is left.
#include "validate/report/timeseries_csv.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>
#include <string>
#include <unistd.h>
#include <vector>

#include "validate/io/output_dir.hpp"

namespace rdyn::validate {
namespace {

namespace fs = std::filesystem;

class TimeseriesCsv : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("rdyn_tscsv_" + std::to_string(::getpid()) + "_" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  fs::path dir_;
};

// Values no short format survives: thirds, π multiples, tiny and huge magnitudes, negatives.
engine::TimeSeries series() {
  engine::TimeSeries ts;
  ts.force_names = {"knee", "hip"};
  ts.column_names = {"p_rocker", "R_crank_x"};
  ts.forces.resize(2);
  ts.columns.resize(2);
  for (int i = 0; i < 6; ++i) {
    ts.t.push_back(0.25 * i);
    ts.q.push_back(M_PI / 3 * (i + 1) + 1e-13);
    ts.qdot.push_back(-1.0 / (3 + i));
    ts.qddot.push_back(std::nextafter(1e-300 * (i + 1), 1.0));
    ts.energy.push_back(12345.678901234567 * std::sqrt(2.0 + i));
    ts.work.push_back(-std::exp(-i) * 1e12);
    ts.forces[0].push_back(std::nextafter(250.0 + i, 1e9));
    ts.forces[1].push_back(-0.1 * i);
    ts.columns[0].push_back(std::sin(0.7 * i));
    ts.columns[1].push_back(std::numeric_limits<double>::denorm_min() * (i + 1));
  }
  return ts;
}

std::vector<std::vector<std::string>> read_csv(const fs::path& p) {
  std::ifstream in(p);
  std::vector<std::vector<std::string>> rows;
  for (std::string line; std::getline(in, line);) {
    std::vector<std::string> cells;
    std::stringstream s(line);
    for (std::string c; std::getline(s, c, ',');) cells.push_back(c);
    rows.push_back(cells);
  }
  return rows;
}

TEST_F(TimeseriesCsv, ReadsBackBitForBitUnderItsHeader) {
  const auto ts = series();
  const fs::path p = dir_ / "timeseries.csv";
  write_timeseries_csv(p.string(), ts);
  const auto rows = read_csv(p);
  ASSERT_EQ(rows.size(), ts.t.size() + 1);
  EXPECT_EQ(rows[0], (std::vector<std::string>{"t", "q", "qdot", "qddot", "energy", "work", "F_knee", "F_hip",
                                                "p_rocker", "R_crank_x"}));
  for (size_t i = 0; i < ts.t.size(); ++i) {
    const auto& r = rows[i + 1];
    ASSERT_EQ(r.size(), 10u) << i;
    auto val = [&](size_t c) { return std::strtod(r[c].c_str(), nullptr); };
    EXPECT_EQ(val(0), ts.t[i]);  // quarters: exact in 10 digits
    EXPECT_EQ(val(1), ts.q[i]) << r[1];
    EXPECT_EQ(val(2), ts.qdot[i]) << r[2];
    EXPECT_EQ(val(3), ts.qddot[i]) << r[3];
    EXPECT_EQ(val(4), ts.energy[i]) << r[4];
    EXPECT_EQ(val(5), ts.work[i]) << r[5];
    EXPECT_EQ(val(6), ts.forces[0][i]) << r[6];
    EXPECT_EQ(val(7), ts.forces[1][i]) << r[7];
    EXPECT_EQ(val(8), ts.columns[0][i]) << r[8];
    EXPECT_EQ(val(9), ts.columns[1][i]) << r[9];
  }
}

// t is written with 10 significant digits (the output grid's times), not 17.
TEST_F(TimeseriesCsv, TimeHasTenSignificantDigits) {
  auto ts = series();
  ts.t[1] = 1.0 / 3.0;
  const fs::path p = dir_ / "timeseries.csv";
  write_timeseries_csv(p.string(), ts);
  EXPECT_EQ(read_csv(p)[2][0], "0.3333333333");
}

TEST_F(TimeseriesCsv, NonFiniteValueIsANumericalErrorAndTheOutputFolderIsNotWritten) {
  for (int column = 0; column < 4; ++column) {
    auto ts = series();
    const double bad = column % 2 ? std::numeric_limits<double>::infinity() : std::nan("");
    if (column == 0) ts.qdot[3] = bad;
    if (column == 1) ts.work[4] = bad;
    if (column == 2) ts.forces[1][2] = bad;
    if (column == 3) ts.columns[0][5] = bad;
    const fs::path out = dir_ / ("run" + std::to_string(column));
    try {
      OutputDir dir(out.string());  // as `rdyn simulate` writes it: a folder committed at the end
      write_timeseries_csv(dir.file("timeseries.csv"), ts);
      dir.commit();
      ADD_FAILURE() << "a non-finite value was written (column case " << column << ")";
    } catch (const models::NumericalError& e) {
      const std::string m = e.what();
      const char* names[] = {"qdot", "work", "force hip", "p_rocker"};
      const char* times[] = {"0.75", "1", "0.5", "1.25"};
      EXPECT_NE(m.find(std::string("non-finite ") + names[column]), std::string::npos) << m;
      EXPECT_NE(m.find(std::string("t = ") + times[column] + " s"), std::string::npos) << m;
    }
    EXPECT_FALSE(fs::exists(out)) << out;
  }
  for (const auto& e : fs::directory_iterator(dir_)) ADD_FAILURE() << "left behind: " << e.path();
}

TEST_F(TimeseriesCsv, AnUnwritablePathIsAnOutputError) {
  EXPECT_THROW(write_timeseries_csv((dir_ / "no" / "such" / "folder" / "t.csv").string(), series()), OutputError);
}

}  // namespace
}  // namespace rdyn::validate
