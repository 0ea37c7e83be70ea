#include "validate/analysis/sweep_part.hpp"

#include <algorithm>
#include <cctype>
#include <cstdio>
#include <map>

#include <fmt/format.h>

#include "models/scene.hpp"
#include "validate/io/argument_error.hpp"

namespace rdyn::validate {

namespace {

constexpr const char* kMagic = "# rdyn-sweep v1 ";
// The sweep's bound on cases (validate/analysis/sweep.cpp checks the axes against it too).
constexpr long kMaxCases = 1000000;

// One CSV record (RFC 4180: a quoted field may hold commas, doubled quotes and line breaks).
struct Record {
  int line = 0;               // 1-based line it starts on
  std::string text;           // as written, without the final line break
  std::vector<std::string> fields;
};

// Splits text into records; `cut` is set when the last record is not ended by a line break
// (a file cut short) or ends inside a quoted field.
std::vector<Record> split_records(const std::string& text, bool& cut) {
  std::vector<Record> out;
  int line = 1;
  size_t i = 0;
  cut = false;
  while (i < text.size()) {  // each pass consumes at least one character
    Record r;
    r.line = line;
    const size_t start = i;
    std::string field;
    bool quoted = false, ended = false;
    while (i < text.size() && !ended) {
      const char c = text[i++];
      if (quoted) {
        if (c == '"') {
          if (i < text.size() && text[i] == '"') {
            field += '"';
            ++i;
          } else {
            quoted = false;
          }
        } else {
          if (c == '\n') ++line;
          field += c;
        }
      } else if (c == '"') {
        quoted = true;
      } else if (c == ',') {
        r.fields.push_back(field);
        field.clear();
      } else if (c == '\n') {
        ++line;
        ended = true;
      } else {
        field += c;
      }
    }
    r.fields.push_back(field);
    r.text = text.substr(start, i - start - (ended ? 1 : 0));
    if (!ended) cut = true;
    out.push_back(std::move(r));
  }
  return out;
}

bool is_hex16(const std::string& s) {
  return s.size() == 16 && std::all_of(s.begin(), s.end(), [](char c) {
           return std::isdigit(static_cast<unsigned char>(c)) || (c >= 'a' && c <= 'f');
         });
}

// A whole non-negative decimal number (no sign, no spaces), at most 18 digits.
bool read_count(const std::string& s, long& v) {
  if (s.empty() || s.size() > 18 ||
      !std::all_of(s.begin(), s.end(), [](char c) { return std::isdigit(static_cast<unsigned char>(c)); }))
    return false;
  v = std::stol(s);
  return true;
}

// "# rdyn-sweep v1 sweep=H scene=H shard=i/N cases=a-b/T"
void parse_metadata(const std::string& line, const std::string& file, SweepIdentity& id, SweepRange& range) {
  auto fail = [&](const std::string& msg) { throw models::SceneError(file, 1, "rdyn-sweep", msg); };
  if (line.rfind(kMagic, 0) != 0)
    fail("not a part of an rdyn sweep (the first line is not '# rdyn-sweep v1 …'; rdyn sweep writes it)");
  std::vector<std::string> words;
  for (size_t p = std::string(kMagic).size(), q; p <= line.size(); p = q + 1) {
    q = line.find(' ', p);
    if (q == std::string::npos) q = line.size();
    words.push_back(line.substr(p, q - p));
  }
  if (words.size() != 4) fail("expected sweep=, scene=, shard= and cases= after 'v1'");
  auto value = [&](size_t k, const std::string& key) {
    if (words[k].rfind(key + "=", 0) != 0) fail("expected " + key + "= as word " + std::to_string(k + 3));
    return words[k].substr(key.size() + 1);
  };
  id.sweep_hex = value(0, "sweep");
  id.scene_hex = value(1, "scene");
  if (!is_hex16(id.sweep_hex) || !is_hex16(id.scene_hex)) fail("sweep= and scene= take 16 lowercase hex digits");
  const std::string shard = value(2, "shard"), cases = value(3, "cases");
  const size_t slash = shard.find('/'), dash = cases.find('-'), over = cases.find('/');
  long i = 0, n = 0, first = 0, end = 0, total = 0;
  if (slash == std::string::npos || !read_count(shard.substr(0, slash), i) || !read_count(shard.substr(slash + 1), n) ||
      n < 1 || n > kMaxCases || i >= n)
    fail("shard= expects i/N with 0 ≤ i < N ≤ " + std::to_string(kMaxCases));
  if (dash == std::string::npos || over == std::string::npos || over < dash ||
      !read_count(cases.substr(0, dash), first) || !read_count(cases.substr(dash + 1, over - dash - 1), end) ||
      !read_count(cases.substr(over + 1), total) || total < 1 || total > kMaxCases)
    fail("cases= expects first-end/total with 1 ≤ total ≤ " + std::to_string(kMaxCases));
  id.total = total;
  range = shard_range(total, static_cast<int>(i), static_cast<int>(n));
  if (range.first != first || range.end != end)
    fail(fmt::format("shard {}/{} of {} cases holds cases {}-{}, not {}-{}", i, n, total, range.first, range.end, first,
                     end));
}

}  // namespace

SweepRange shard_range(long total, int shard, int shards) {
  const long per = (total + shards - 1) / shards;
  SweepRange r;
  r.shard = shard;
  r.shards = shards;
  r.first = std::min(total, per * shard);
  r.end = std::min(total, r.first + per);
  return r;
}

std::string sweep_csv(const SweepIdentity& id, const SweepRange& range, const std::string& header,
                      const std::vector<std::string>& rows) {
  std::string csv = fmt::format("{}sweep={} scene={} shard={}/{} cases={}-{}/{}\n{}\n", kMagic, id.sweep_hex,
                                id.scene_hex, range.shard, range.shards, range.first, range.end, id.total, header);
  for (const auto& r : rows) csv += r + "\n";
  return csv;
}

long SweepPart::first_missing() const {
  long expect = range.first;
  for (const long c : cases) {
    if (c != expect) return expect;
    ++expect;
  }
  return expect;
}

SweepPart parse_sweep_part(const std::string& text, const std::string& file) {
  SweepPart p;
  p.file = file;
  const size_t eol = text.find('\n');
  parse_metadata(text.substr(0, eol), file, p.id, p.range);
  if (eol == std::string::npos) throw models::SceneError(file, 1, "rdyn-sweep", "the file ends after its first line");
  bool cut = false;
  std::vector<Record> records = split_records(text.substr(eol + 1), cut);
  for (auto& r : records) ++r.line;  // the metadata line came first
  if (records.empty()) throw models::SceneError(file, 2, "header", "no column header");
  if (cut) throw models::SceneError(file, records.back().line, "row", "the file is cut short (no final line break)");
  const Record& head = records.front();
  // case, the axes (at least one), status and the result columns (six of a calibrating sweep,
  // seven of a drive sweep, the last `error`), with a peak_<column> per --peak before `error`:
  // status is the last field of that name (a peak column's name starts with peak_).
  const size_t n = head.fields.size();
  size_t status_at = 0;
  for (size_t k = 0; k < n; ++k)
    if (head.fields[k] == "status") status_at = k;
  const size_t results = status_at + 1 < n && head.fields[status_at + 1] == "drive_rms_Nm" ? 8 : 7;
  bool peaks_ok = n >= status_at + results;
  for (size_t k = status_at + results - 1; peaks_ok && k + 1 < n; ++k)
    peaks_ok = head.fields[k].rfind("peak_", 0) == 0;
  if (head.fields.empty() || head.fields[0] != "case" || status_at < 2 || !peaks_ok || head.fields[n - 1] != "error")
    throw models::SceneError(file, head.line, "header", "expected case,<axes>,status,… as written by rdyn sweep");
  p.header = head.text;
  long previous = p.range.first - 1;
  for (size_t k = 1; k < records.size(); ++k) {
    const Record& r = records[k];
    auto fail = [&](const std::string& field, const std::string& msg) {
      throw models::SceneError(file, r.line, field, msg);
    };
    if (r.fields.size() != n) fail("row", fmt::format("{} fields; the header has {}", r.fields.size(), n));
    long c = 0;
    if (!read_count(r.fields[0], c)) fail("case", "not a case number: '" + r.fields[0] + "'");
    if (c < p.range.first || c >= p.range.end)
      fail("case", fmt::format("case {} is outside this part's cases {}-{}", c, p.range.first, p.range.end));
    if (c <= previous) fail("case", fmt::format("case {} after case {}: rows out of order or doubled", c, previous));
    const std::string& status = r.fields[status_at];
    if (status != "ok" && status != "error") fail("status", "expected ok or error, got '" + status + "'");
    // As rdyn writes them: a failed case says why, a case that ran has no error (an edit ok →
    // error with an empty reason was merged).
    if ((status == "error") == r.fields[n - 1].empty())
      fail("error", status == "error" ? "a case with status error gives its reason" : "a case with status ok has no error");
    if (status == "error") ++p.failed;
    previous = c;
    p.cases.push_back(c);
    p.rows.push_back(r.text);
  }
  return p;
}

MergedSweep merge_sweep_parts(const std::vector<SweepPart>& parts) {
  if (parts.empty()) throw ArgumentError("--merge: no parts given");
  const SweepPart& ref = parts.front();
  // Every case's part, in case order: a case in two parts is named with both files.
  std::map<long, const SweepPart*> owner_of_first;
  for (const auto& p : parts) {
    auto mismatch = [&](const std::string& field, const std::string& what) {
      throw models::SceneError(p.file, field == "header" ? 2 : 1, field,
                               what + " differs from " + ref.file + ": the parts are not of one sweep");
    };
    if (p.id.sweep_hex != ref.id.sweep_hex) mismatch("sweep", "the sweep (scene, axes, options)");
    if (p.id.scene_hex != ref.id.scene_hex) mismatch("scene", "the scene hash");
    if (p.id.total != ref.id.total) mismatch("cases", "the number of cases");
    if (p.header != ref.header) mismatch("header", "the column header");
    if (!p.complete())
      throw models::SceneError(p.file, 0, "rows",
                               fmt::format("shard {}/{} is partial: case {} of its cases {}-{} is missing; run the "
                                           "shard again",
                                           p.range.shard, p.range.shards, p.first_missing(), p.range.first,
                                           p.range.end));
    if (p.range.first == p.range.end) continue;  // an empty shard (more shards than cases) holds nothing
    const auto [it, fresh] = owner_of_first.emplace(p.range.first, &p);
    if (!fresh)
      throw models::SceneError(p.file, 0, "cases",
                               fmt::format("case {} is also in {}: a part given twice?", p.range.first, it->second->file));
  }
  MergedSweep m;
  std::vector<std::string> rows;
  long expect = 0;
  for (const auto& [first, part] : owner_of_first) {
    if (first > expect)
      throw ArgumentError(
          fmt::format("--merge: cases {}-{} are in no part given (of {} cases in all)", expect, first, ref.id.total));
    if (first < expect)
      throw models::SceneError(part->file, 0, "cases",
                               fmt::format("case {} is also in another part (parts of different shard counts overlap)",
                                           first));
    rows.insert(rows.end(), part->rows.begin(), part->rows.end());
    m.failed += part->failed;
    expect = part->range.end;
  }
  if (expect != ref.id.total)
    throw ArgumentError(fmt::format("--merge: cases {}-{} are in no part given (of {} cases in all)", expect,
                                    ref.id.total, ref.id.total));
  m.cases = expect;
  m.csv = sweep_csv(ref.id, shard_range(ref.id.total, 0, 1), ref.header, rows);
  return m;
}

}  // namespace rdyn::validate
