// Headless Chromium for the tests of rdyn's pages (Debian's `chromium`, started with an argument
// vector, no network services, a fresh profile per call): the DOM the page's script produced at
// `page#t=T`, a screenshot, and the data-x/data-y of the drawn elements.
#pragma once

#include <filesystem>
#include <map>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "tests/validate/run_rdyn.hpp"

namespace rdyn::test {

struct Xy {
  double x = 0, y = 0;
};

// Every element carrying `attr`: its value (plus ".a"/".b" from data-side for loops) → data-x,
// data-y. A page with several animations: pass the part of the DOM of one.
inline std::map<std::string, Xy> positions(const std::string& dom, const std::string& attr) {
  std::map<std::string, Xy> out;
  const std::regex el("<[a-z]+ " + attr + "=\"([^\"]+)\"[^>]*>");
  const std::regex x("data-x=\"([^\"]+)\""), y("data-y=\"([^\"]+)\""), side("data-side=\"([^\"]+)\"");
  for (auto it = std::sregex_iterator(dom.begin(), dom.end(), el); it != std::sregex_iterator(); ++it) {
    const std::string tag = (*it)[0];
    std::smatch mx, my, ms;
    if (!std::regex_search(tag, mx, x) || !std::regex_search(tag, my, y)) continue;
    std::string key = (*it)[1];
    if (std::regex_search(tag, ms, side)) key += "." + ms[1].str();
    out[key] = {std::stod(mx[1]), std::stod(my[1])};
  }
  return out;
}

// A time as the page's address gives it (round-trip digits).
inline std::string fmt_t(double t) {
  std::ostringstream s;
  s.precision(17);
  s << t;
  return s.str();
}

class Chromium {
 public:
  explicit Chromium(std::filesystem::path dir) : dir_(std::move(dir)) {}
  // Chromium as root, headless, no network services, a fresh profile per call.
  std::vector<std::string> argv(const std::string& what) {
    const std::filesystem::path profile = dir_ / ("profile" + std::to_string(++profiles_));
    return {"chromium", "--headless", "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
            "--disable-background-networking", "--disable-component-update", "--disable-sync",
            "--user-data-dir=" + profile.string(), "--virtual-time-budget=3000", what};
  }
  // The DOM of page#t=T after its scripts ran.
  std::string dump_dom(const std::filesystem::path& page, double t) {
    auto a = argv("--dump-dom");
    a.push_back("file://" + page.string() + "#t=" + fmt_t(t));
    const auto r = run_argv(a, dir_);
    EXPECT_EQ(r.status, 0) << "chromium (Debian package `chromium`) did not run: " << r.err.substr(0, 500);
    return r.out;
  }
  // A PNG of page#t=T at width × height.
  RdynRun screenshot(const std::filesystem::path& page, double t, const std::filesystem::path& png, int width,
                     int height) {
    auto a = argv("--screenshot=" + png.string());
    a.insert(a.end() - 1, "--window-size=" + std::to_string(width) + "," + std::to_string(height));
    a.push_back("file://" + page.string() + "#t=" + fmt_t(t));
    return run_argv(a, dir_);
  }

 private:
  std::filesystem::path dir_;
  int profiles_ = 0;
};

}  // namespace rdyn::test
