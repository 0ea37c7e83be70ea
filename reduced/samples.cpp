#include "reduced/samples.hpp"

#include "models/scene_hash.hpp"
#include "models/scene_yaml.hpp"

#include <algorithm>
#include <cmath>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <string>
#include <fstream>
#include <sstream>

#include <fmt/format.h>

namespace rdyn::reduced {

namespace {
constexpr double kPi = 3.14159265358979323846;
}

int Samples::column(const std::string& name) const {
  for (size_t c = 0; c < names.size(); ++c)
    if (names[c] == name) return static_cast<int>(c);
  return -1;
}

int Samples::require(const std::string& name) const {
  const int c = column(name);
  if (c >= 0) return c;
  // A table read from a file names the file and its header line: that is where the column is missing.
  const std::string shown = name.substr(0, 80);
  if (file.empty()) throw TableError("the reduced table has no column '" + shown + "', which the scene needs");
  throw TableError(fmt::format("{}:{}: the column header has no column '{}', which the scene needs (its constraint "
                               "forces, loads and outputs): extract the table again from this scene with `rdyn "
                               "extract`",
                               file, header_line, shown));
}

const std::vector<double>* Samples::roots_of(const std::string& column) const {
  for (const auto& r : roots)
    if (r.first == column) return &r.second;
  return nullptr;
}

void Samples::add(const std::string& name, std::vector<double> values) {
  if (column(name) >= 0) throw TableError("duplicate column '" + name + "'");
  names.push_back(name);
  columns.push_back(std::move(values));
}

Samples select_columns(const Samples& s, const std::vector<std::string>& keep) {
  auto kept = [&](const std::string& name) { return std::find(keep.begin(), keep.end(), name) != keep.end(); };
  Samples out = s;  // the grid and metadata (the columns, a few hundred values at 10°, are rebuilt)
  out.names.clear(), out.columns.clear(), out.roots.clear();
  for (size_t c = 0; c < s.names.size(); ++c)
    if (kept(s.names[c])) out.add(s.names[c], s.columns[c]);
  for (const auto& r : s.roots)
    if (kept(r.first)) out.roots.push_back(r);
  return out;
}

namespace {

constexpr const char* kHeader = "# rdyn-table v1 ";
constexpr const char* kOldHeader = "# rdyn reduced table:";

// The scene name as one metadata token (informational: the hash identifies the scene).
std::string token(const std::string& name) {
  std::string t = name.empty() ? "-" : name;
  for (char& c : t)
    if (c <= ' ' || c == '=' || c == ',' || c == 0x7f) c = '_';
  return t;
}

// Column names a reduced table can carry (samples.hpp): fixed names and prefixed families.
bool known_column(const std::string& n) {
  if (n == "m1" || n == "m2" || n == "Q_cons" || n == "V") return true;
  for (const char* prefix : {"me1_", "me2_", "Qx_cons_", "rx_", "r_", "wx_", "w_", "p_", "k_", "tau_", "Qpf_", "Qxpf_"}) {
    const size_t len = std::char_traits<char>::length(prefix);
    if (n.size() > len && n.compare(0, len, prefix) == 0) return true;
  }
  return false;
}

}  // namespace

std::string format_samples_csv(const Samples& s) {
  if (!s.scene_hash) throw TableError("the samples record no scene hash; extract them from a scene");
  std::string t = fmt::format("{}scene={:016x} name={} method={} periodic={} q0={:.17g} step={:.17g} grid_deg={:.17g}\n",
                              kHeader, *s.scene_hash, token(s.scene), token(s.method), s.periodic ? 1 : 0, s.q0, s.step,
                              s.revolute ? s.step * 180.0 / kPi : s.step);
  if (!s.periodic && (!s.min_edge.empty() || !s.max_edge.empty())) {
    t.pop_back();
    t += fmt::format(" edges={},{}\n", token(s.min_edge.empty() ? "unknown" : s.min_edge),
                     token(s.max_edge.empty() ? "unknown" : s.max_edge));
  }
  if (!s.singular_q.empty()) {
    t += "# singular:";
    for (double q : s.singular_q) t += fmt::format(" {:.17g}", q);
    t += '\n';
  }
  for (const auto& [force, qs] : s.poles) {
    t += fmt::format("# pole {}:", force);
    for (double q : qs) t += fmt::format(" {:.17g}", q);
    t += '\n';
  }
  for (const auto& [col, rs] : s.roots) {
    t += fmt::format("# roots {}:", col);
    for (double r : rs) t += fmt::format(" {:.17g}", r);
    t += '\n';
  }
  t += s.revolute ? "q_deg" : "q_m";
  for (const auto& n : s.names) t += "," + n;
  t += '\n';
  for (size_t i = 0; i < s.q.size(); ++i) {
    t += fmt::format("{:.17g}", s.revolute ? s.q[i] * 180.0 / kPi : s.q[i]);
    for (const auto& c : s.columns) t += fmt::format(",{:.17g}", c[i]);
    t += '\n';
  }
  // The content checksum (FNV-1a of the whole text without it) goes at the end of the first line:
  // an edited value, row or metadata field is refused on reading instead of silently changing
  // the model (parse_samples_csv).
  const std::string sum = fmt::format(" content={:016x}", models::fnv1a64(t));
  t.insert(t.find('\n'), sum);
  return t;
}

void write_samples_csv(const std::string& path, const Samples& s) {
  const std::string text = format_samples_csv(s);
  std::FILE* f = std::fopen(path.c_str(), "w");
  if (!f) throw TableError(path + ": cannot open for writing: " + std::strerror(errno));
  const bool written = std::fwrite(text.data(), 1, text.size(), f) == text.size();
  const int err = errno;
  if (std::fclose(f) != 0 || !written) throw TableError(path + ": cannot write: " + std::strerror(written ? errno : err));
}

namespace {

// Largest magnitude of any number in a table: products of two such values and a speed squared
// stay far from overflow (1e100·1e100·1e6 < 1.8e308).
constexpr double kMaxTableMagnitude = 1e100;

// Reads a table's text line by line (without their \n or \r\n), failing with the file and line.
struct TableReader {
  const std::string& text;
  const std::string& name;
  size_t pos = 0;
  long ln = 0;
  std::string line;

  [[noreturn]] void fail(long at, const std::string& msg) const {
    throw TableError(fmt::format("{}:{}: {}", name, at, msg));
  }
  bool next_line() {
    if (pos >= text.size()) return false;
    size_t end = text.find('\n', pos);
    if (end == std::string::npos) end = text.size();
    line.assign(text, pos, end - pos);
    if (!line.empty() && line.back() == '\r') line.pop_back();
    pos = end + 1;
    ++ln;
    return true;
  }
  double number(const std::string& cell, const std::string& what) const {
    // Decimal only, as rdyn writes (%.17g): strtod also reads hex ("0x10" was 16 in a table
    // without a checksum) and "inf"/"nan".
    const bool decimal = cell.find_first_not_of("0123456789+-.eE") == std::string::npos;
    char* end = nullptr;
    const double v = std::strtod(cell.c_str(), &end);
    if (cell.empty() || !decimal || end != cell.c_str() + cell.size() || !std::isfinite(v))
      fail(ln, fmt::format("{}: not a finite decimal number: '{}'", what, cell.substr(0, 40)));
    // The reduced model multiplies table values with each other and with q̇²: a value near the
    // double's limit (m1 = 1e308) overflowed there into NaN, reported without file or line.
    if (std::abs(v) > kMaxTableMagnitude)
      fail(ln, fmt::format("{}: {} is beyond ±{:g}, no mechanism's reduced parameter", what, cell.substr(0, 40),
                           kMaxTableMagnitude));
    return v;
  }
};

// The first line: the header tag and its key=value metadata.
void read_metadata(TableReader& r, Samples& s) {
  if (!r.next_line()) r.fail(1, "empty file: not an rdyn reduced table");
  if (r.line.rfind(kOldHeader, 0) == 0)
    r.fail(1, "this table was written by an older rdyn and does not record the scene it was extracted from; "
              "re-extract it with `rdyn extract`");
  if (r.line.rfind(kHeader, 0) != 0)
    r.fail(1, fmt::format("not an rdyn reduced table (the first line must start with '{}')", kHeader));
  std::istringstream meta(r.line.substr(std::char_traits<char>::length(kHeader)));
  bool have_q0 = false, have_step = false, have_periodic = false;
  double grid = NAN;
  std::vector<std::string> seen;
  for (std::string kv; meta >> kv;) {
    const auto eq = kv.find('=');
    if (eq == std::string::npos) r.fail(1, "malformed metadata '" + kv.substr(0, 40) + "' (key=value)");
    const std::string k = kv.substr(0, eq), v = kv.substr(eq + 1);
    // A key given twice would let the last silently win (a hand edit appending periodic=0).
    if (std::find(seen.begin(), seen.end(), k) != seen.end())
      r.fail(1, "metadata field '" + k.substr(0, 40) + "' is given twice");
    seen.push_back(k);
    if (k == "scene") {
      if (v.size() != 16 || v.find_first_not_of("0123456789abcdef") != std::string::npos)
        r.fail(1, "field 'scene': the scene hash must be 16 lowercase hexadecimal digits");
      s.scene_hash = std::stoull(v, nullptr, 16);
    } else if (k == "name") {
      s.scene = v;
    } else if (k == "method") {
      s.method = v;
    } else if (k == "periodic") {
      if (v != "0" && v != "1") r.fail(1, "field 'periodic' must be 0 or 1");
      s.periodic = v == "1";
      have_periodic = true;
    } else if (k == "q0") {
      s.q0 = r.number(v, "field 'q0'");
      have_q0 = true;
    } else if (k == "step") {
      s.step = r.number(v, "field 'step'");
      have_step = true;
    } else if (k == "edges") {
      const auto comma = v.find(',');
      if (comma == std::string::npos) r.fail(1, "field 'edges' must be <min>,<max>");
      for (std::string* e : {&s.min_edge, &s.max_edge}) {
        std::string w = e == &s.min_edge ? v.substr(0, comma) : v.substr(comma + 1);
        for (char& c : w)
          if (c == '_') c = ' ';
        if (w != "dead point" && w != "declared limit" && w != "point force meeting" && w != "unknown")
          r.fail(1, "field 'edges': each edge is dead_point, declared_limit, point_force_meeting or unknown");
        *e = w == "unknown" ? "" : w;
      }
    } else if (k == "grid_deg") {
      grid = r.number(v, "field 'grid_deg'");
    } else if (k == "content") {
      // checked by check_content before the metadata is read
    } else {
      r.fail(1, "unknown metadata field '" + k.substr(0, 40) + "'");
    }
  }
  if (!s.scene_hash) r.fail(1, "field 'scene' (the scene hash) is missing; re-extract the table with `rdyn extract`");
  if (!have_q0 || !have_step || !have_periodic) r.fail(1, "fields 'q0', 'step' and 'periodic' are required");
  if (!(s.step > 0)) r.fail(1, "field 'step' must be positive");
  if (std::isfinite(grid) && std::abs(grid - s.step * 180.0 / kPi) > 1e-9 * grid && std::abs(grid - s.step) > 1e-12 * grid)
    r.fail(1, "field 'grid_deg' disagrees with 'step'");
}

// Optional "# singular: q...", "# pole <force>: q..." and "# roots <column>: r1 r2 ..." lines;
// leaves the reader on the line after them (false: none left).
bool read_annotations(TableReader& r, Samples& s) {
  bool have_line = r.next_line();
  while (have_line && (r.line.rfind("# roots ", 0) == 0 || r.line.rfind("# singular:", 0) == 0 ||
                       r.line.rfind("# pole ", 0) == 0)) {
    const bool singular = r.line.rfind("# singular:", 0) == 0;
    const bool pole = r.line.rfind("# pole ", 0) == 0;
    const auto colon = r.line.find(':');
    if (!singular && colon == std::string::npos)
      r.fail(r.ln, pole ? "malformed pole line (# pole <force>: values)" : "malformed roots line (# roots <column>: values)");
    std::vector<double> vals;
    std::istringstream in(r.line.substr(colon + 1));
    for (std::string v; in >> v;) {
      if (static_cast<long>(vals.size()) >= kMaxTableRows)
        r.fail(r.ln, fmt::format("more than {} values on one line", kMaxTableRows));
      vals.push_back(r.number(v, singular ? "singular angle" : pole ? "pole" : "root"));
    }
    for (size_t i = 1; i < vals.size(); ++i)
      if (!(vals[i] > vals[i - 1])) r.fail(r.ln, "values must be strictly increasing");
    if (singular) {
      s.singular_q.insert(s.singular_q.end(), vals.begin(), vals.end());
    } else if (pole) {
      const std::string force = r.line.substr(7, colon - 7);
      for (const auto& p : s.poles)
        if (p.first == force) r.fail(r.ln, "duplicate pole line for force '" + force.substr(0, 40) + "'");
      if (static_cast<long>(s.poles.size()) >= kMaxTableColumns) r.fail(r.ln, "too many pole lines");
      if (vals.empty()) r.fail(r.ln, "a pole line needs at least one value");
      s.poles.emplace_back(force, std::move(vals));
    } else {
      const std::string col = r.line.substr(8, colon - 8);
      if (s.roots_of(col)) r.fail(r.ln, "duplicate roots line for column '" + col.substr(0, 40) + "'");
      if (static_cast<long>(s.roots.size()) >= kMaxTableColumns) r.fail(r.ln, "too many roots lines");
      s.roots.emplace_back(col, std::move(vals));
    }
    have_line = r.next_line();
  }
  return have_line;
}

// The column header on the reader's line: q_deg or q_m, then known, distinct column names.
std::vector<std::string> read_column_header(TableReader& r, Samples& s) {
  std::vector<std::string> header;
  std::istringstream h(r.line);
  for (std::string cell; std::getline(h, cell, ',');) {
    if (static_cast<long>(header.size()) > kMaxTableColumns) r.fail(r.ln, fmt::format("more than {} columns", kMaxTableColumns));
    header.push_back(cell);
  }
  if (!r.line.empty() && r.line.back() == ',') header.emplace_back();
  if (header.empty() || (header[0] != "q_deg" && header[0] != "q_m")) r.fail(r.ln, "first column must be q_deg or q_m");
  s.revolute = header[0] == "q_deg";
  s.header_line = r.ln;
  for (size_t c = 1; c < header.size(); ++c) {
    if (!known_column(header[c]))
      r.fail(r.ln, fmt::format("unknown column '{}' (m1, m2, Q_cons, V, me1_*, me2_*, Qx_cons_*, r_*, rx_*, w_*, wx_*, p_*, k_*, tau_*, Qpf_*, Qxpf_*)",
                               header[c].substr(0, 40)));
    if (s.column(header[c]) >= 0) r.fail(r.ln, "duplicate column '" + header[c].substr(0, 40) + "'");
    s.names.push_back(header[c]);
  }
  for (const auto& [col, rs] : s.roots)
    if (s.column(col) < 0) r.fail(s.header_line, "roots are given for column '" + col.substr(0, 40) + "', which is absent");
  return header;
}

// The data rows, one value per header column, within the table limits.
void read_rows(TableReader& r, const std::vector<std::string>& header, Samples& s) {
  s.columns.assign(s.names.size(), {});
  while (r.next_line()) {
    if (r.line.empty()) continue;
    if (static_cast<long>(s.q.size()) >= kMaxTableRows)
      r.fail(r.ln, fmt::format("more than {} grid points (the finest extraction grid is 0.01°)", kMaxTableRows));
    if (static_cast<long>((s.q.size() + 1) * header.size()) > kMaxTableValues)
      r.fail(r.ln, fmt::format("more than {} values", kMaxTableValues));
    size_t c = 0, start = 0;
    for (;; ++c) {
      const size_t comma = r.line.find(',', start);
      const std::string cell = r.line.substr(start, comma == std::string::npos ? std::string::npos : comma - start);
      if (c >= header.size()) r.fail(r.ln, fmt::format("more values than the {} columns of the header", header.size()));
      const double v = r.number(cell, "column '" + header[c].substr(0, 40) + "'");
      if (c == 0) s.q.push_back(s.revolute ? v * kPi / 180.0 : v);
      else s.columns[c - 1].push_back(v);
      if (comma == std::string::npos) break;
      start = comma + 1;
    }
    if (c + 1 != header.size()) r.fail(r.ln, fmt::format("{} values, the header has {}", c + 1, header.size()));
  }
}

// What the rows must satisfy: enough points, a positive m1, the grid of q0 and step (one turn
// when periodic).
void check_rows(const TableReader& r, const Samples& s) {
  const long header_line = s.header_line;
  if (s.q.size() < 4) r.fail(r.ln, "a reduced table needs at least 4 grid points");
  // The reduced inertia is positive wherever the mechanism moves (Eksergian divides by it):
  // refused here with its line, not later as a model that cannot be built.
  if (const int c = s.column("m1"); c >= 0)
    for (size_t i = 0; i < s.q.size(); ++i)
      if (!(s.columns[c][i] > 0))
        r.fail(header_line + 1 + static_cast<long>(i),
               fmt::format("column 'm1' (the reduced inertia, kg·m² or kg) must be positive, got {:g}; extract the "
                           "table again with `rdyn extract`",
                           s.columns[c][i]));
  const double tol = 1e-9 * std::max(1.0, std::abs(s.q0) + s.step * static_cast<double>(s.q.size()));
  if (std::abs(s.q[0] - s.q0) > tol) r.fail(header_line + 1, "the first grid point differs from field 'q0'");
  for (size_t i = 1; i < s.q.size(); ++i)
    if (!(s.q[i] > s.q[i - 1]) || std::abs(s.q[i] - s.q[i - 1] - s.step) > tol)
      r.fail(header_line + 1 + static_cast<long>(i), "grid points must increase, equally spaced by field 'step'");
  if (s.periodic && !s.revolute) r.fail(1, "a periodic table has a revolute coordinate (q_deg)");
  if (s.periodic && std::abs(s.step * static_cast<double>(s.q.size()) - 2 * kPi) > 1e-9)
    r.fail(1, "a periodic table must cover exactly one turn (step × points = 360°)");
}

// The content checksum of the first line (" content=<16 hex digits>", format_samples_csv) against
// the text without it, line ends normalised to \n and a final \n (an editor that writes CRLF or
// drops the last newline changes no value). Returns whether the table has one; a mismatch is a
// TableError: a value, row or metadata field was changed after extraction.
bool check_content(const TableReader& r, const std::string& text) {
  const size_t eol = std::min(text.find('\n'), text.size());
  const size_t at = text.rfind(" content=", eol);
  if (at == std::string::npos || at > eol) return false;
  const size_t end = std::min(text.find(' ', at + 1), eol);
  std::string value = text.substr(at + 9, end - at - 9);
  if (!value.empty() && value.back() == '\r') value.pop_back();
  if (value.size() != 16 || value.find_first_not_of("0123456789abcdef") != std::string::npos)
    r.fail(1, "field 'content': the checksum must be 16 lowercase hexadecimal digits");
  std::string body = text.substr(0, at) + text.substr(end);
  std::string normal;
  normal.reserve(body.size() + 1);
  for (size_t i = 0; i < body.size(); ++i)
    if (!(body[i] == '\r' && i + 1 < body.size() && body[i + 1] == '\n')) normal += body[i];
  while (!normal.empty() && normal.back() == '\r') normal.pop_back();
  if (normal.empty() || normal.back() != '\n') normal += '\n';
  if (fmt::format("{:016x}", models::fnv1a64(normal)) != value)
    r.fail(1, "the table's content does not match its checksum (field 'content'): a value, row or metadata field was "
              "changed after `rdyn extract` wrote it, which would silently change the model; extract it again");
  return true;
}

}  // namespace

Samples parse_samples_csv(const std::string& raw, const std::string& name) {
  if (static_cast<long long>(raw.size()) > kMaxTableBytes)
    throw TableError(fmt::format("{}:1: the table has {} bytes, more than the limit of {} bytes", name, raw.size(),
                                 kMaxTableBytes));
  const std::string text = models::normalise_text_encoding(raw);
  TableReader r{text, name, 0, 0, {}};
  Samples s;
  s.file = name;
  s.content_checked = check_content(r, text);
  read_metadata(r, s);
  if (!read_annotations(r, s)) r.fail(r.ln + 1, "missing the column header line (q_deg or q_m, then the columns)");
  const auto header = read_column_header(r, s);
  read_rows(r, header, s);
  check_rows(r, s);
  return s;
}

Samples read_samples_csv(const std::string& path) {
  std::error_code ec;
  const auto size = std::filesystem::file_size(path, ec);
  if (ec) throw TableError(path + ": cannot open reduced table: " + ec.message());
  if (size > static_cast<std::uintmax_t>(kMaxTableBytes))
    throw TableError(fmt::format("{}: the table has {} bytes, more than the limit of {} bytes", path, size,
                                 kMaxTableBytes));
  std::ifstream in(path, std::ios::binary);
  if (!in) throw TableError(path + ": cannot open reduced table");
  std::string text(static_cast<size_t>(size), '\0');
  in.read(text.data(), static_cast<std::streamsize>(size));
  if (in.gcount() != static_cast<std::streamsize>(size)) throw TableError(path + ": cannot read reduced table");
  return parse_samples_csv(text, path);
}

}  // namespace rdyn::reduced
