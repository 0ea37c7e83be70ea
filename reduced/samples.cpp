#include "reduced/samples.hpp"

#include <cmath>
#include <cstdio>
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
  if (c < 0) throw TableError("reduced table has no column '" + name + "'");
  return c;
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

void write_samples_csv(const std::string& path, const Samples& s) {
  std::FILE* f = std::fopen(path.c_str(), "w");
  if (!f) throw TableError(path + ": cannot open for writing");
  fmt::print(f, "# rdyn reduced table: scene={} method={} periodic={} q0={:.17g} step={:.17g}\n", s.scene,
             s.method, s.periodic ? 1 : 0, s.q0, s.step);
  if (!s.singular_q.empty()) {
    fmt::print(f, "# singular:");
    for (double q : s.singular_q) fmt::print(f, " {:.17g}", q);
    std::fputc('\n', f);
  }
  for (const auto& [col, rs] : s.roots) {
    fmt::print(f, "# roots {}:", col);
    for (double r : rs) fmt::print(f, " {:.17g}", r);
    std::fputc('\n', f);
  }
  fmt::print(f, "{}", s.revolute ? "q_deg" : "q_m");
  for (const auto& n : s.names) fmt::print(f, ",{}", n);
  std::fputc('\n', f);
  for (size_t i = 0; i < s.q.size(); ++i) {
    fmt::print(f, "{:.17g}", s.revolute ? s.q[i] * 180.0 / kPi : s.q[i]);
    for (const auto& c : s.columns) fmt::print(f, ",{:.17g}", c[i]);
    std::fputc('\n', f);
  }
  if (std::fclose(f) != 0) throw TableError(path + ": write failed");
}

Samples read_samples_csv(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw TableError(path + ": cannot open reduced table");
  auto fail = [&](int line, const std::string& msg) {
    throw TableError(fmt::format("{}:{}: {}", path, line, msg));
  };
  Samples s;
  std::string line;
  int ln = 1;
  if (!std::getline(in, line) || line.rfind("# rdyn reduced table:", 0) != 0)
    fail(1, "not an rdyn reduced table (missing '# rdyn reduced table:' line)");
  {
    std::istringstream meta(line.substr(21));
    for (std::string kv; meta >> kv;) {
      const auto eq = kv.find('=');
      if (eq == std::string::npos) fail(1, "malformed metadata '" + kv + "'");
      const std::string k = kv.substr(0, eq), v = kv.substr(eq + 1);
      try {
        if (k == "scene") s.scene = v;
        else if (k == "method") s.method = v;
        else if (k == "periodic") s.periodic = v == "1";
        else if (k == "q0") s.q0 = std::stod(v);
        else if (k == "step") s.step = std::stod(v);
      } catch (const std::exception&) {
        fail(1, "malformed metadata '" + kv + "'");
      }
    }
  }
  ++ln;
  // Optional "# roots <column>: r1 r2 ..." lines.
  while (std::getline(in, line) && (line.rfind("# roots ", 0) == 0 || line.rfind("# singular:", 0) == 0)) {
    if (line.rfind("# singular:", 0) == 0) {
      std::istringstream vals(line.substr(11));
      for (double x; vals >> x;) s.singular_q.push_back(x);
      ++ln;
      continue;
    }
    const auto colon = line.find(':');
    if (colon == std::string::npos) fail(ln, "malformed roots line");
    std::vector<double> rs;
    std::istringstream vals(line.substr(colon + 1));
    for (std::string v; vals >> v;) {
      char* end = nullptr;
      const double x = std::strtod(v.c_str(), &end);
      if (*end != '\0' || !std::isfinite(x)) fail(ln, "malformed root '" + v + "'");
      rs.push_back(x);
    }
    s.roots.emplace_back(line.substr(8, colon - 8), rs);
    ++ln;
  }
  if (line.empty() && in.eof()) fail(ln, "missing header");
  std::vector<std::string> header;
  {
    std::istringstream h(line);
    for (std::string cell; std::getline(h, cell, ',');) header.push_back(cell);
  }
  if (header.empty() || (header[0] != "q_deg" && header[0] != "q_m")) fail(ln, "first column must be q_deg or q_m");
  s.revolute = header[0] == "q_deg";
  s.names.assign(header.begin() + 1, header.end());
  s.columns.assign(s.names.size(), {});
  while (std::getline(in, line)) {
    ++ln;
    if (line.empty()) continue;
    std::istringstream row(line);
    std::vector<double> vals;
    for (std::string cell; std::getline(row, cell, ',');) {
      char* end = nullptr;
      const double v = std::strtod(cell.c_str(), &end);
      if (end == cell.c_str() || *end != '\0' || !std::isfinite(v)) fail(ln, "not a finite number: '" + cell + "'");
      vals.push_back(v);
    }
    if (vals.size() != header.size())
      fail(ln, fmt::format("{} values, the header has {}", vals.size(), header.size()));
    s.q.push_back(s.revolute ? vals[0] * kPi / 180.0 : vals[0]);
    for (size_t c = 0; c < s.names.size(); ++c) s.columns[c].push_back(vals[c + 1]);
  }
  if (s.q.size() < 4) fail(ln, "a reduced table needs at least 4 grid points");
  if (!(s.step > 0)) fail(1, "step must be positive");
  for (size_t i = 1; i < s.q.size(); ++i)
    if (std::abs(s.q[i] - s.q[i - 1] - s.step) > 1e-9 * std::max(1.0, std::abs(s.q[i])))
      fail(static_cast<int>(i) + 3, "grid points must be equally spaced by step");
  if (s.periodic && std::abs(s.step * static_cast<double>(s.q.size()) - 2 * kPi) > 1e-9)
    fail(1, "a periodic table must cover exactly one turn");
  return s;
}

}  // namespace rdyn::reduced
