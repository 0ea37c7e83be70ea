#include "reduced/samples.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>

#include <fmt/format.h>

#include "reduced/table.hpp"

namespace rdyn::reduced {
namespace {

constexpr const char* kHash = "0123456789abcdef";

// A valid periodic table text: 8 points of 45°, columns m1, m2, r_crank; `header` and `rows`
// replace the column line and the data when given.
std::string table_text(const std::string& meta_extra = "", const std::string& header = "q_deg,m1,m2,r_crank",
                       const std::string& rows = "") {
  std::string t = fmt::format("# rdyn-table v1 scene={} name=x method=kinetostatic periodic=1 q0=0 "
                              "step=0.78539816339744828 grid_deg=45{}\n",
                              kHash, meta_extra);
  t += "# roots r_crank: 1.5 4.5\n" + header + "\n";
  if (!rows.empty()) return t + rows;
  for (int i = 0; i < 8; ++i) t += fmt::format("{},{},{},{}\n", 45 * i, 1 + 0.1 * i, 0.01 * i, std::cos(i * M_PI / 4));
  return t;
}

std::string error_of(const std::string& text) {
  try {
    parse_samples_csv(text, "t.csv");
  } catch (const TableError& e) {
    return e.what();
  }
  return "";
}

// select_columns keeps the named columns in the samples' order (a name they lack is skipped) with
// their roots; each interpolant fits a column on its own, so every kept column's cubics are those of
// the whole table bit for bit, periodic (fourier resampled at 0.25°, cubic, akima, linear) and over
// a range.
TEST(Samples, SelectedColumnsFitAsInTheWholeTable) {
  for (const bool periodic : {true, false}) {
    Samples s;
    s.periodic = periodic;
    s.step = 2 * M_PI / 36;
    for (int i = 0; i < 36; ++i) s.q.push_back(i * s.step);
    for (int c = 0; c < 5; ++c) {
      std::vector<double> v;
      for (const double q : s.q) v.push_back((1 + c) * std::exp(std::sin(q + c)) + 0.3 * std::cos((c + 1) * q));
      s.add("c" + std::to_string(c), v);
    }
    s.roots = {{"c1", {0.5, 2.5}}, {"c2", {1.0, 4.0}}};
    s.min_conditioning = 0.25;
    const Samples part = select_columns(s, {"c3", "absent", "c1", "c4"});
    EXPECT_EQ(part.names, (std::vector<std::string>{"c1", "c3", "c4"}));
    EXPECT_EQ(part.columns[1], s.columns[3]);
    ASSERT_EQ(part.roots.size(), 1u);
    EXPECT_EQ(part.roots[0], s.roots[0]);
    EXPECT_EQ(part.q, s.q);
    EXPECT_EQ(part.periodic, periodic);
    EXPECT_EQ(part.min_conditioning, 0.25);
    for (const auto interp : {Interpolation::Fourier, Interpolation::CubicSpline, Interpolation::Akima,
                              Interpolation::Linear}) {
      const Table whole = build_table(s, interp), fitted = build_table(part, interp);
      ASSERT_EQ(fitted.cols, 3);
      ASSERT_EQ(fitted.intervals, whole.intervals);
      EXPECT_EQ(fitted.fit, whole.fit);
      EXPECT_EQ(fitted.step, whole.step);
      for (int k = 0; k < fitted.cols; ++k) {
        const int w = whole.column(fitted.names[k]);
        for (int iv = 0; iv < fitted.intervals; ++iv)
          for (int p = 0; p < 4; ++p)
            ASSERT_EQ(fitted.coef[(static_cast<size_t>(iv) * fitted.cols + k) * 4 + p],
                      whole.coef[(static_cast<size_t>(iv) * whole.cols + w) * 4 + p])
                << fitted.names[k] << " interval " << iv << " " << interpolation_name(interp);
      }
    }
  }
}

TEST(Samples, CsvRoundTripKeepsEveryBitTheRootsAndTheSceneHash) {
  Samples s;
  s.scene = "x y";  // a name with a space is written as one token
  s.scene_hash = 0xfedcba9876543210ull;
  s.method = "kinetostatic";
  s.step = 2 * M_PI / 8;
  s.q0 = s.step;
  for (int i = 0; i < 8; ++i) s.q.push_back((i + 1) * s.step);
  s.add("m1", {1, 2, 3, 4, 5, 6, 7, 8.123456789012345});
  s.add("m2", {0.1, -0.2, 0.3, -0.4, 0.5, -0.6, 0.7, -1e-300});
  s.roots.emplace_back("m2", std::vector<double>{0.1, 3.3});
  s.singular_q = {2 * s.step};
  s.poles.emplace_back("rod_axial", std::vector<double>{2 * s.step});
  const std::string path = ::testing::TempDir() + "/samples_test.csv";
  write_samples_csv(path, s);
  const Samples r = read_samples_csv(path);
  EXPECT_EQ(r.names, s.names);
  EXPECT_EQ(r.columns, s.columns);
  ASSERT_TRUE(r.scene_hash);
  EXPECT_EQ(*r.scene_hash, *s.scene_hash);
  EXPECT_EQ(r.scene, "x_y");
  EXPECT_EQ(r.file, path);
  EXPECT_EQ(r.q0, s.q0);
  EXPECT_EQ(r.step, s.step);
  EXPECT_EQ(r.singular_q, s.singular_q);
  EXPECT_EQ(r.poles, s.poles);
  ASSERT_NE(r.roots_of("m2"), nullptr);
  EXPECT_EQ(*r.roots_of("m2"), s.roots[0].second);
  for (size_t i = 0; i < s.q.size(); ++i) EXPECT_NEAR(r.q[i], s.q[i], 1e-15);
  std::ifstream in(path);
  std::string first;
  std::getline(in, first);
  EXPECT_EQ(first.rfind("# rdyn-table v1 scene=fedcba9876543210 ", 0), 0u) << first;
  std::remove(path.c_str());
}

// The content checksum: any edit of a value, a row or a metadata field after writing is refused
// naming line 1; line-end conversions are not edits; a table without one is read, unchecked.
TEST(Samples, TheContentChecksumRefusesEditsButNotLineEndings) {
  Samples s;
  s.scene = "x";
  s.scene_hash = 0x0123456789abcdefull;
  s.method = "kinetostatic";
  s.step = 2 * M_PI / 8;
  for (int i = 0; i < 8; ++i) s.q.push_back(i * s.step);
  s.add("m1", {1, 2, 3, 4, 5, 6, 7, 8});
  s.add("m2", {0.1, -0.2, 0.3, -0.4, 0.5, -0.6, 0.7, -0.8});
  s.periodic = true;
  const std::string text = format_samples_csv(s);
  ASSERT_NE(text.substr(0, text.find('\n')).find(" content="), std::string::npos) << text;
  EXPECT_TRUE(parse_samples_csv(text, "t.csv").content_checked);
  auto refused = [](const std::string& t) { return error_of(t).find("t.csv:1: the table's content does not match"); };
  // m1 of the third row (after the metadata and column lines) from 3 to 9.
  std::string edited = text;
  size_t row = 0;
  for (int i = 0; i < 4; ++i) row = edited.find('\n', row) + 1;
  const size_t m1 = edited.find(',', row) + 1;
  ASSERT_EQ(edited.substr(m1, 2), "3,") << edited;
  edited[m1] = '9';
  EXPECT_NE(refused(edited), std::string::npos) << error_of(edited);
  std::string flag = text;
  flag.replace(flag.find("periodic=1"), 10, "periodic=0");
  EXPECT_NE(refused(flag), std::string::npos);
  std::string crlf;
  for (char c : text) crlf += c == '\n' ? std::string("\r\n") : std::string(1, c);
  EXPECT_TRUE(parse_samples_csv(crlf, "t.csv").content_checked);
  EXPECT_TRUE(parse_samples_csv(text.substr(0, text.size() - 1), "t.csv").content_checked);  // no last newline
  // An editor's byte-order mark and CR-only line ends change no value: read, checked, the same.
  const auto bom = parse_samples_csv("\xEF\xBB\xBF" + text, "t.csv");
  EXPECT_TRUE(bom.content_checked);
  EXPECT_EQ(bom.columns, s.columns);
  std::string cr = text;
  std::replace(cr.begin(), cr.end(), '\n', '\r');
  const auto mac = parse_samples_csv(cr, "t.csv");
  EXPECT_TRUE(mac.content_checked);
  EXPECT_EQ(mac.columns, s.columns);
  // An edit behind a byte-order mark is still refused.
  EXPECT_NE(refused("\xEF\xBB\xBF" + edited), std::string::npos);
  std::string unchecked = text;
  unchecked.erase(unchecked.find(" content="), 25);
  EXPECT_FALSE(parse_samples_csv(unchecked, "t.csv").content_checked);
  std::string malformed = text;
  malformed.replace(malformed.find(" content=") + 9, 3, "XYZ");
  EXPECT_NE(error_of(malformed).find("field 'content'"), std::string::npos) << error_of(malformed);
}

TEST(Samples, SamplesWithoutASceneHashAreNotWritten) {
  Samples s;
  s.step = 1;
  EXPECT_THROW(write_samples_csv(::testing::TempDir() + "/no_hash.csv", s), TableError);
}

TEST(Samples, TheValidFixtureParses) {
  const Samples s = parse_samples_csv(table_text(), "t.csv");
  EXPECT_EQ(s.q.size(), 8u);
  EXPECT_EQ(*s.scene_hash, 0x0123456789abcdefull);
  EXPECT_EQ(s.names, (std::vector<std::string>{"m1", "m2", "r_crank"}));
  // Windows line ends are accepted too.
  std::string crlf;
  for (char c : table_text()) {
    if (c == '\n') crlf += '\r';
    crlf += c;
  }
  EXPECT_EQ(parse_samples_csv(crlf, "t.csv").columns, s.columns);
}

// Point-force columns (Qpf_<load>, Qxpf_<force>_<load>) are known to the reader and keep every
// bit through the text; a near miss of their prefix is still unknown.
TEST(Samples, PointForceColumnsRoundTrip) {
  std::string rows;
  for (int i = 0; i < 8; ++i)
    rows += fmt::format("{},{},{},{},{:.17g},{:.17g}\n", 45 * i, 1 + 0.1 * i, 0.01 * i, std::cos(i * M_PI / 4),
                        -0.1 * std::sin(i * M_PI / 4) / 3, 1.0 / (i + 3));
  const Samples s = parse_samples_csv(table_text("", "q_deg,m1,m2,r_crank,Qpf_glute,Qxpf_knee_glute", rows), "t.csv");
  ASSERT_EQ(s.names.size(), 5u);
  const Samples back = parse_samples_csv(format_samples_csv(s), "back.csv");
  EXPECT_EQ(back.names, s.names);
  EXPECT_EQ(back.columns, s.columns);
  EXPECT_EQ(back.columns[s.column("Qpf_glute")][5], -0.1 * std::sin(5 * M_PI / 4) / 3);
  EXPECT_NE(error_of(table_text("", "q_deg,m1,m2,Qpfglute", rows)).find("unknown column 'Qpfglute'"),
            std::string::npos);
}

TEST(Samples, OlderTablesWithoutTheSceneHashAreRefusedWithAdviceToReExtract) {
  const std::string e = error_of("# rdyn reduced table: scene=x method=k periodic=1 q0=0 step=1\nq_deg,m1\n0,1\n");
  EXPECT_NE(e.find("t.csv:1:"), std::string::npos) << e;
  EXPECT_NE(e.find("re-extract"), std::string::npos) << e;
  const std::string missing = error_of("# rdyn-table v1 periodic=1 q0=0 step=0.78539816339744828\nq_deg,m1\n");
  EXPECT_NE(missing.find("scene hash"), std::string::npos) << missing;
  EXPECT_NE(missing.find("re-extract"), std::string::npos) << missing;
}

TEST(Samples, MalformedTablesNameFileLineAndField) {
  std::string ragged = table_text("", "q_deg,m1,m2,r_crank", "0,1,0,1\n45,1,0\n");
  struct Case {
    const char* what;
    std::string text;
    const char* expected;  // substring of the message
  };
  std::string uneven, decreasing, nan_value, inf_value, more_values, negative_m1;
  for (int i = 0; i < 8; ++i) {
    negative_m1 += fmt::format("{},{},0,1\n", 45 * i, i == 3 ? "-2" : "1");
    uneven += fmt::format("{},1,0,1\n", i == 5 ? 226 : 45 * i);
    decreasing += fmt::format("{},1,0,1\n", i == 3 ? 90 : 45 * i);
    nan_value += fmt::format("{},{},0,1\n", 45 * i, i == 2 ? "nan" : "1");
    inf_value += fmt::format("{},1,{},1\n", 45 * i, i == 6 ? "-inf" : "0");
    more_values += fmt::format("{},1,0,1{}\n", 45 * i, i == 1 ? ",7" : "");
  }
  const std::vector<Case> cases = {
      {"empty", "", "t.csv:1: empty file"},
      {"not a table", "t,q\n1,2\n", "t.csv:1: not an rdyn reduced table"},
      {"bad hash", "# rdyn-table v1 scene=xyz periodic=1 q0=0 step=1\n", "t.csv:1: field 'scene'"},
      {"unknown metadata", table_text(" colour=red"), "t.csv:1: unknown metadata field 'colour'"},
      {"metadata twice", table_text(" periodic=0"), "t.csv:1: metadata field 'periodic' is given twice"},
      {"beyond any mechanism", table_text("", "q_deg,m1,m2,r_crank", "0,1e308,0,1\n"),
       "t.csv:4: column 'm1': 1e308 is beyond ±1e+100"},
      {"step not finite", "# rdyn-table v1 scene=0123456789abcdef periodic=1 q0=0 step=inf\n", "field 'step'"},
      {"grid_deg disagrees", table_text("", "q_deg,m1,m2,r_crank").replace(table_text("", "q_deg,m1,m2,r_crank").find("grid_deg=45"), 11, "grid_deg=40"),
       "field 'grid_deg' disagrees"},
      {"no column header", "# rdyn-table v1 scene=0123456789abcdef periodic=1 q0=0 step=1\n", "t.csv:2: missing"},
      {"first column", table_text("", "t,m1,m2,r_crank"), "t.csv:3: first column must be q_deg or q_m"},
      {"unknown column", table_text("", "q_deg,m1,m2,colour"), "t.csv:3: unknown column 'colour'"},
      {"empty column name", table_text("", "q_deg,m1,m2,r_crank,"), "t.csv:3: unknown column ''"},
      {"duplicate column", table_text("", "q_deg,m1,m1,r_crank"), "t.csv:3: duplicate column 'm1'"},
      {"roots of an absent column", table_text("", "q_deg,m1,m2,r_other"), "roots are given for column 'r_crank'"},
      {"ragged row", ragged, "t.csv:5: 3 values, the header has 4"},
      {"more values", table_text("", "q_deg,m1,m2,r_crank", more_values), "t.csv:5: more values than the 4 columns"},
      {"nan", table_text("", "q_deg,m1,m2,r_crank", nan_value), "t.csv:6: column 'm1': not a finite decimal number: 'nan'"},
      {"inf", table_text("", "q_deg,m1,m2,r_crank", inf_value), "t.csv:10: column 'm2': not a finite decimal number: '-inf'"},
      {"trailing garbage", table_text("", "q_deg,m1,m2,r_crank", "0,1x,0,1\n"), "not a finite decimal number: '1x'"},
      {"hex", table_text("", "q_deg,m1,m2,r_crank", "0,0x10,0,1\n"), "not a finite decimal number: '0x10'"},
      {"uneven grid", table_text("", "q_deg,m1,m2,r_crank", uneven), "t.csv:9: grid points must increase, equally"},
      {"decreasing grid", table_text("", "q_deg,m1,m2,r_crank", decreasing), "t.csv:7: grid points must increase"},
      {"negative m1", table_text("", "q_deg,m1,m2,r_crank", negative_m1),
       "t.csv:7: column 'm1' (the reduced inertia, kg·m² or kg) must be positive, got -2"},
      {"too few points", table_text("", "q_deg,m1,m2,r_crank", "0,1,0,1\n45,1,0,1\n"), "at least 4 grid points"},
      {"not a full turn", table_text("", "q_deg,m1,m2,r_crank", "0,1,0,1\n45,1,0,1\n90,1,0,1\n135,1,0,1\n"),
       "exactly one turn"},
      {"roots not increasing",
       "# rdyn-table v1 scene=0123456789abcdef periodic=1 q0=0 step=1\n# roots r_a: 2 1\n", "t.csv:2: values must"},
      {"root not finite",
       "# rdyn-table v1 scene=0123456789abcdef periodic=1 q0=0 step=1\n# roots r_a: 1 nan\n", "t.csv:2: root"},
      {"pole without values", "# rdyn-table v1 scene=0123456789abcdef periodic=1 q0=0 step=1\n# pole f:\n",
       "t.csv:2: a pole line needs at least one value"},
      {"pole twice",
       "# rdyn-table v1 scene=0123456789abcdef periodic=1 q0=0 step=1\n# pole f: 1\n# pole f: 2\n",
       "t.csv:3: duplicate pole line for force 'f'"},
      {"pole malformed", "# rdyn-table v1 scene=0123456789abcdef periodic=1 q0=0 step=1\n# pole f 1\n",
       "t.csv:2: malformed pole line"},
  };
  for (const auto& c : cases) {
    const std::string e = error_of(c.text);
    EXPECT_NE(e.find(c.expected), std::string::npos) << c.what << ": got '" << e << "'";
  }
}

TEST(Samples, AMissingColumnNamesTheFileAndItsHeaderLine) {
  std::string rows;
  for (int i = 0; i < 8; ++i) rows += fmt::format("{},1,0,1\n", 45 * i);
  const Samples s = parse_samples_csv(table_text("", "q_deg,m1,m2,r_crank", rows), "t.csv");
  EXPECT_EQ(s.header_line, 3);
  try {
    s.require("me1_knee");
    ADD_FAILURE() << "found";
  } catch (const TableError& e) {
    EXPECT_EQ(std::string(e.what()).rfind("t.csv:3: the column header has no column 'me1_knee', which the scene needs",
                                          0),
              0u)
        << e.what();
  }
}

TEST(Samples, SizeLimitsAreCheckedWhileReading) {
  // One row more than the finest extraction grid: refused at that row, not after reading it all.
  std::string rows;
  for (long i = 0; i <= kMaxTableRows; ++i) rows += fmt::format("{},1,1\n", i * 0.01);
  const std::string e = error_of(table_text("", "q_deg,m1,r_crank", rows));
  EXPECT_NE(e.find(fmt::format("t.csv:{}: more than {} grid points", kMaxTableRows + 4, kMaxTableRows)),
            std::string::npos)
      << e.substr(0, 200);
  std::string header = "q_deg";
  for (long c = 0; c <= kMaxTableColumns; ++c) header += fmt::format(",r_{}", c);
  EXPECT_NE(error_of(table_text("", header)).find("more than 4096 columns"), std::string::npos);
  // A file over the byte limit is refused from its size alone (a sparse file: nothing is read).
  const std::string path = ::testing::TempDir() + "/huge_table.csv";
  { std::ofstream(path) << "x"; }
  std::filesystem::resize_file(path, static_cast<std::uintmax_t>(kMaxTableBytes) + 1);
  try {
    read_samples_csv(path);
    ADD_FAILURE() << "a table over the byte limit was read";
  } catch (const TableError& err) {
    EXPECT_NE(std::string(err.what()).find("more than the limit"), std::string::npos) << err.what();
  }
  std::remove(path.c_str());
  EXPECT_THROW(read_samples_csv(::testing::TempDir() + "/no_such_table.csv"), TableError);
}

}  // namespace
}  // namespace rdyn::reduced
