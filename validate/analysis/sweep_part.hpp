// The sweep's CSV as self-describing parts (issue #28): every file `rdyn sweep` writes — the
// whole sweep or one shard of it — starts with one metadata line that names the sweep and the
// cases the file holds, then the column header, then one row per case in case order:
//
//   # rdyn-sweep v1 sweep=<16 hex> scene=<16 hex> shard=<i>/<N> cases=<first>-<end>/<total>
//   case,<axis keys>,status,…
//   <first>,…
//
// `sweep` fingerprints everything that decides the rows (the expanded base scene, the axes and
// their values, the calibration target, load and grid); `scene` is the base scene's mechanism
// hash (models/scene_hash.hpp, what a reduced table records). A part is complete when it holds
// every case of [first, end) once, in order; parts merge when they name the same sweep and
// header and together hold every case of [0, total) exactly once. The merged file is what one
// process would have written (shard 0/1, cases 0-total/total): both go through sweep_csv.
#pragma once

#include <string>
#include <vector>

namespace rdyn::validate {

// Which sweep a file belongs to.
struct SweepIdentity {
  std::string sweep_hex;  // 16 lowercase hex digits: FNV-1a of the sweep's defining text
  std::string scene_hex;  // 16 lowercase hex digits: the base scene's mechanism hash
  long total = 0;         // cases in the whole sweep
};

// Which cases of the sweep a file holds: shard i of N, cases [first, end).
struct SweepRange {
  int shard = 0, shards = 1;
  long first = 0, end = 0;
};

// The cases of shard i of N: contiguous blocks of ceil(total/N), the last ones shorter or empty.
SweepRange shard_range(long total, int shard, int shards);

// The whole file: metadata line, header line, rows (each without its newline; a row may hold a
// quoted line break), every line ended by '\n'.
std::string sweep_csv(const SweepIdentity& id, const SweepRange& range, const std::string& header,
                      const std::vector<std::string>& rows);

// A part as read from a file.
struct SweepPart {
  std::string file;
  SweepIdentity id;
  SweepRange range;
  std::string header;
  std::vector<long> cases;        // case index of each row, strictly increasing, inside range
  std::vector<std::string> rows;  // the rows' text, as written
  long failed = 0;                // rows with status "error"
  bool complete() const { return static_cast<long>(rows.size()) == range.end - range.first; }
  // The first case of the range that has no row (range.end when complete).
  long first_missing() const;
};

// Reads a part; anything that is not a sweep file, or a row out of order, out of range,
// malformed or cut short (the text does not end with a line break) is a SceneError naming the
// file, the line and what is wrong. Missing cases are not an error here (see complete()).
SweepPart parse_sweep_part(const std::string& text, const std::string& file);

struct MergedSweep {
  std::string csv;
  long cases = 0, failed = 0;
};

// The parts of one sweep as one file in case order (what the one-process sweep writes). A part
// of another sweep or header, a part with cases missing, or a case in two parts is a SceneError
// naming the file and cases; cases in no part given (a part left out) are an ArgumentError.
MergedSweep merge_sweep_parts(const std::vector<SweepPart>& parts);

}  // namespace rdyn::validate
