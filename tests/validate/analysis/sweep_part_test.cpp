// Sweep parts: shard ranges, reading a part (RFC 4180 rows, cut or disordered files) and merging
// parts into the whole sweep, on hand-written files.
#include "validate/analysis/sweep_part.hpp"

#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "models/scene.hpp"
#include "validate/io/argument_error.hpp"

namespace rdyn::validate {
namespace {

const std::string kHeader = "case,a,status,drive_torque_Nm,mean_cadence_hz,mean_power_w,peak_knee_force_N,"
                            "speed_fluctuation,error";
const std::string kMeta = "# rdyn-sweep v1 sweep=00000000000000aa scene=00000000000000bb ";

// Case k's row as rdyn writes it; case 3 failed with a message holding a comma, quotes and a line break.
std::string row(int k) {
  if (k == 3) return "3,0.4,error,,,,,,\"loop \"\"C\"\" cannot close,\nat q = 10°\"";
  return std::to_string(k) + ",0." + std::to_string(k + 1) + ",ok,1,2,3,4,5,";
}

std::string file_of(const std::string& shard, const std::string& cases, int first, int end) {
  std::string t = kMeta + "shard=" + shard + " cases=" + cases + "\n" + kHeader + "\n";
  for (int k = first; k < end; ++k) t += row(k) + "\n";
  return t;
}

// Blocks of ceil(total/N): every case in exactly one shard, in order, for uneven splits and
// more shards than cases.
TEST(SweepPart, ShardRangesCoverEveryCaseOnce) {
  for (long total : {1L, 2L, 7L, 10L, 1000L})
    for (int shards : {1, 2, 3, 4, 7, 13}) {
      long expect = 0;
      for (int i = 0; i < shards; ++i) {
        const SweepRange r = shard_range(total, i, shards);
        EXPECT_EQ(r.first, expect) << total << " " << i << "/" << shards;
        EXPECT_LE(r.end - r.first, (total + shards - 1) / shards);
        EXPECT_GE(r.end, r.first);
        expect = r.end;
      }
      EXPECT_EQ(expect, total) << total << " over " << shards;
    }
}

TEST(SweepPart, ReadsQuotedRowsAndCountsFailures) {
  const std::string text = file_of("1/2", "3-5/5", 3, 5);
  const SweepPart p = parse_sweep_part(text, "p1.csv");
  EXPECT_EQ(p.id.sweep_hex, "00000000000000aa");
  EXPECT_EQ(p.id.scene_hex, "00000000000000bb");
  EXPECT_EQ(p.id.total, 5);
  EXPECT_EQ(p.range.first, 3);
  EXPECT_EQ(p.range.end, 5);
  EXPECT_EQ(p.header, kHeader);
  ASSERT_EQ(p.rows.size(), 2u);
  EXPECT_EQ(p.rows[0], row(3));  // the quoted line break stays inside the row
  EXPECT_EQ(p.cases, (std::vector<long>{3, 4}));
  EXPECT_EQ(p.failed, 1);
  EXPECT_TRUE(p.complete());
}

TEST(SweepPart, APartWithCasesMissingIsPartial) {
  std::string text = file_of("0/2", "0-3/5", 0, 3);
  text.erase(text.find(row(1)), row(1).size() + 1);
  const SweepPart p = parse_sweep_part(text, "p0.csv");
  EXPECT_FALSE(p.complete());
  EXPECT_EQ(p.first_missing(), 1);
  const SweepPart empty = parse_sweep_part(file_of("0/2", "0-3/5", 0, 0), "p0.csv");
  EXPECT_EQ(empty.first_missing(), 0);
}

// What each malformed file is refused for: the line and field of the SceneError.
TEST(SweepPart, MalformedPartsAreRefusedWithTheirLine) {
  struct Bad {
    std::string text;
    int line;
    std::string field;
  };
  const std::string good = file_of("0/1", "0-5/5", 0, 5);
  std::string swapped = file_of("0/1", "0-5/5", 0, 2);
  swapped += row(4) + "\n" + row(2) + "\n";  // out of order
  std::string doubled = file_of("0/1", "0-5/5", 0, 2) + row(1) + "\n";
  std::string short_row = file_of("0/1", "0-5/5", 0, 1) + "1,0.2,ok,1\n";
  std::string bad_status = file_of("0/1", "0-5/5", 0, 1) + "1,0.2,done,1,2,3,4,5,\n";
  std::string silent_error = file_of("0/1", "0-5/5", 0, 1) + "1,0.2,error,1,2,3,4,5,\n";  // edited ok → error
  std::string ok_with_error = file_of("0/1", "0-5/5", 0, 1) + "1,0.2,ok,1,2,3,4,5,diverged\n";
  const std::vector<Bad> cases{
      {good.substr(0, good.size() - 1), 8, "row"},                                 // cut: no final line break
      {good.substr(0, good.find("at q")), 6, "row"},                               // cut inside a quoted field
      {swapped, 6, "case"},
      {doubled, 5, "case"},
      {short_row, 4, "row"},
      {bad_status, 4, "status"},
      {silent_error, 4, "error"},
      {ok_with_error, 4, "error"},
      {file_of("1/2", "3-5/5", 0, 1), 3, "case"},                                  // outside its range
      {file_of("1/2", "2-5/5", 3, 5), 1, "rdyn-sweep"},                            // not shard 1/2's cases
      {file_of("2/2", "3-5/5", 3, 5), 1, "rdyn-sweep"},                            // i ≥ N
      {"case,a,status\n0,1,ok\n", 1, "rdyn-sweep"},                                // an older sweep file
      {kMeta + "shard=0/1 cases=0-1/1\n", 2, "header"},                            // no header
      {kMeta + "shard=0/1 cases=0-1/1\nx,y\n", 2, "header"},
      {"# rdyn-sweep v1 sweep=XYZ scene=00000000000000bb shard=0/1 cases=0-1/1\n" + kHeader + "\n", 1, "rdyn-sweep"},
  };
  for (const auto& b : cases) {
    try {
      parse_sweep_part(b.text, "p.csv");
      ADD_FAILURE() << "accepted:\n" << b.text;
    } catch (const models::SceneError& e) {
      EXPECT_EQ(e.file(), "p.csv");
      EXPECT_EQ(e.line(), b.line) << e.what() << "\n" << b.text;
      EXPECT_EQ(e.field(), b.field) << e.what();
    }
  }
}

std::vector<SweepPart> parts_of(const std::vector<std::string>& texts) {
  std::vector<SweepPart> parts;
  for (size_t k = 0; k < texts.size(); ++k) parts.push_back(parse_sweep_part(texts[k], "p" + std::to_string(k)));
  return parts;
}

// Parts given in any order, an empty shard among them, make the file written by hand for the
// whole sweep.
TEST(SweepPart, PartsInAnyOrderMergeIntoTheWholeSweep) {
  const std::string whole = file_of("0/1", "0-5/5", 0, 5);
  const std::string p0 = file_of("0/3", "0-2/5", 0, 2), p1 = file_of("1/3", "2-4/5", 2, 4),
                    p2 = file_of("2/3", "4-5/5", 4, 5);
  const MergedSweep m = merge_sweep_parts(parts_of({p2, p0, p1}));
  EXPECT_EQ(m.csv, whole);
  EXPECT_EQ(m.cases, 5);
  EXPECT_EQ(m.failed, 1);
  // Five cases over seven shards: shards 5 and 6 are empty and merge to nothing.
  std::vector<std::string> seven;
  for (int i = 0; i < 7; ++i) {
    const int first = std::min(i, 5), end = std::min(i + 1, 5);
    seven.push_back(file_of(std::to_string(i) + "/7", std::to_string(first) + "-" + std::to_string(end) + "/5", first, end));
  }
  EXPECT_EQ(merge_sweep_parts(parts_of(seven)).csv, whole);
  // Parts of two shard counts must still hold every case: 0/3 (cases 0-2) with 1/2 (3-5) leaves
  // case 2 in no part.
  EXPECT_THROW(merge_sweep_parts(parts_of({p0, file_of("1/2", "3-5/5", 3, 5)})), ArgumentError);
}

TEST(SweepPart, PartsOfAnotherSweepMissingOrDoubledAreRefused) {
  const std::string p0 = file_of("0/2", "0-3/5", 0, 3), p1 = file_of("1/2", "3-5/5", 3, 5);
  EXPECT_THROW(merge_sweep_parts({}), ArgumentError);
  EXPECT_THROW(merge_sweep_parts(parts_of({p0})), ArgumentError);  // cases 3-5 in no part
  EXPECT_THROW(merge_sweep_parts(parts_of({p1})), ArgumentError);  // cases 0-3 in no part
  auto field_of = [](const std::vector<std::string>& texts) {
    try {
      merge_sweep_parts(parts_of(texts));
    } catch (const models::SceneError& e) {
      return e.field() + " in " + e.file();
    }
    return std::string("accepted");
  };
  EXPECT_EQ(field_of({p0, p1, p1}), "cases in p2");
  std::string other = p1;
  other.replace(other.find("sweep=00000000000000aa"), 22, "sweep=00000000000000ab");
  EXPECT_EQ(field_of({p0, other}), "sweep in p1");
  std::string scene = p1;
  scene.replace(scene.find("scene=00000000000000bb"), 22, "scene=00000000000000bc");
  EXPECT_EQ(field_of({p0, scene}), "scene in p1");
  std::string header = p1;
  header.replace(header.find("case,a,"), 7, "case,b,");
  EXPECT_EQ(field_of({p0, header}), "header in p1");
  EXPECT_EQ(field_of({p0, file_of("1/2", "3-5/5", 3, 4)}), "rows in p1");  // partial: case 4 missing
  // 0/2 (0-3) and 1/3 (2-4) overlap in case 2.
  EXPECT_EQ(field_of({p0, file_of("1/3", "2-4/5", 2, 4), file_of("2/3", "4-5/5", 4, 5)}), "cases in p1");
}


// Every prefix of a part and every byte of it replaced by a comma, a quote, a line break or a
// letter: read as a part or refused with a SceneError, never another exception or a crash.
TEST(SweepPart, DamagedPartsAreReadOrRefusedNeverCrash) {
  const std::string good = file_of("0/1", "0-5/5", 0, 5);
  long refused = 0, read = 0;
  auto attempt = [&](const std::string& text) {
    try {
      const SweepPart p = parse_sweep_part(text, "p.csv");
      EXPECT_LE(p.rows.size(), 5u);
      ++read;
    } catch (const models::SceneError&) {
      ++refused;
    }
  };
  for (size_t n = 0; n < good.size(); ++n) attempt(good.substr(0, n));
  for (size_t i = 0; i < good.size(); ++i)
    for (const char c : {',', '"', '\n', 'x', '9'}) {
      std::string t = good;
      t[i] = c;
      attempt(t);
    }
  EXPECT_GT(refused, 0);
  EXPECT_GT(read, 0);
}

}  // namespace
}  // namespace rdyn::validate
