// `rdyn animate` and `rdyn inspect --svg` in a real browser: headless Chromium (Debian's
// `chromium`, started with an argument vector) loads animation.html#t=T and dumps the DOM the
// page's script produced; the joints' data-x/data-y must be the model's own pose at that time
// (the run recomputed in this process, placed by models::calc_pose) to 1e-9 m, the ground pivots
// on their ground points, the loops closed, the moving joints moving; a screenshot must not be
// a single colour.
#include "validate/cli/animate_command.hpp"

#include <unistd.h>
#include <zlib.h>

#include <cmath>
#include <cstdint>
#include <filesystem>
#include <map>
#include <regex>
#include <set>
#include <sstream>

#include <gtest/gtest.h>

#include "models/pose.hpp"
#include "models/scene_yaml.hpp"
#include "tests/validate/browser.hpp"
#include "tests/validate/run_rdyn.hpp"
#include "validate/analysis/mechanism_run.hpp"

namespace rdyn::validate {
namespace {

namespace fs = std::filesystem;
using test::run_argv;
using test::run_rdyn;

using test::fmt_t;
using test::positions;
using test::Xy;

class Browser : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("rdyn_animate_" + std::to_string(::getpid()) + "_" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
    browser_ = test::Chromium(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  std::vector<std::string> chromium(const std::string& what) { return browser_.argv(what); }
  std::string dump_dom(const fs::path& page, double t) { return browser_.dump_dom(page, t); }
  fs::path dir_;
  test::Chromium browser_{""};  // profiles in dir_ (SetUp)
};

// The checks of the issue at times `times` of a run of `scene` (`model`, duration, interval).
void check_page(const std::string& scene_arg, const std::string& model, double duration, double dt,
                const std::vector<double>& times, const fs::path& dir,
                std::function<std::string(const fs::path&, double)> dump) {
  const auto r = run_rdyn({"animate", scene_arg, "--model", model, "--duration", fmt_t(duration), "--dt-out",
                           fmt_t(dt), "--out", (dir / "anim").string()},
                          dir);
  ASSERT_EQ(r.status, 0) << r.err;
  const fs::path page = dir / "anim" / "animation.html";
  ASSERT_TRUE(fs::exists(page));
  const auto s = models::load_scene(scene_arg, {});
  const auto ts = simulate_every_joint(s, model, duration, dt);  // the model's own run, in this process
  std::map<std::string, Xy> first;
  std::set<std::string> moved;
  for (double t : times) {
    const std::string dom = dump(page, t);
    // The row shown: nearest to T, clamped to the run (the page's rule).
    const double tc = std::clamp(t, ts.t.front(), ts.t.back());
    size_t row = 0;
    for (size_t i = 0; i < ts.t.size(); ++i)
      if (std::abs(ts.t[i] - tc) < std::abs(ts.t[row] - tc)) row = i;
    std::smatch m;
    ASSERT_TRUE(std::regex_search(dom, m, std::regex("<body data-t=\"([^\"]+)\"")));
    EXPECT_NEAR(std::stod(m[1]), ts.t[row], 1e-12) << "T = " << t;
    const auto pose = models::calc_pose(s, joint_coordinates(s, ts, row));
    const auto joints = positions(dom, "data-joint");
    ASSERT_EQ(joints.size(), s.joints.size()) << "T = " << t;
    for (size_t j = 0; j < s.joints.size(); ++j) {
      const auto& got = joints.at(s.joints[j].name);
      EXPECT_NEAR(got.x, pose.joints[j].x, 1e-9) << s.joints[j].name << " at T = " << t;
      EXPECT_NEAR(got.y, pose.joints[j].y, 1e-9) << s.joints[j].name << " at T = " << t;
      if (!first.count(s.joints[j].name)) first[s.joints[j].name] = got;
      const auto& f0 = first.at(s.joints[j].name);
      if (std::hypot(got.x - f0.x, got.y - f0.y) > 1e-3) moved.insert(s.joints[j].name);
    }
    // Ground pivots on their ground points, and the joint hanging there too.
    const auto pivots = positions(dom, "data-ground-pivot");
    for (const auto& jt : s.joints) {
      if (jt.parent != models::kGround || jt.type != models::JointType::Revolute) continue;
      EXPECT_EQ(pivots.at(jt.name).x, jt.parent_point.x);
      EXPECT_EQ(pivots.at(jt.name).y, jt.parent_point.y);
      EXPECT_NEAR(joints.at(jt.name).x, jt.parent_point.x, 1e-9) << jt.name << " at T = " << t;
      EXPECT_NEAR(joints.at(jt.name).y, jt.parent_point.y, 1e-9) << jt.name << " at T = " << t;
    }
    // Loops closed: both sides' points meet (the full model holds them to its tolerance; the
    // reduced model to its table's interpolation).
    const auto loops = positions(dom, "data-loop");
    for (const auto& l : s.loops) {
      const auto a = loops.at(l.name + ".a"), bb = loops.at(l.name + ".b");
      EXPECT_LT(std::hypot(a.x - bb.x, a.y - bb.y), model == "full" ? 1e-8 : 1e-3) << l.name << " at T = " << t;
    }
    for (const auto& body : s.bodies) EXPECT_NE(dom.find("data-body=\"" + body.name + "\""), std::string::npos);
  }
  // Every joint not fixed to ground moves over the run.
  for (const auto& jt : s.joints)
    if (jt.parent != models::kGround) {
      EXPECT_TRUE(moved.count(jt.name)) << jt.name << " never moved";
    }
}

TEST_F(Browser, FourbarPosesAreTheFullModels) {
  check_page("fourbar", "full", 1.0, 0.01, {0.0, 0.25, 0.5, 0.73, 1.0, 7.0, -1.0}, dir_,
             [this](const fs::path& p, double t) { return dump_dom(p, t); });
}

TEST_F(Browser, FourbarPosesAreTheReducedModels) {
  check_page("fourbar", "reduced", 1.0, 0.01, {0.0, 0.5, 1.0}, dir_,
             [this](const fs::path& p, double t) { return dump_dom(p, t); });
}

TEST_F(Browser, ChainOfSevenBodiesAndThreeLoops) {
  check_page(std::string(RDYN_SCENES) + "/chains/chain-3.yaml", "full", 1.0, 0.01, {0.0, 0.3, 0.6, 1.0},
             dir_, [this](const fs::path& p, double t) { return dump_dom(p, t); });
}

// Decodes an 8-bit, non-interlaced RGB or RGBA PNG (what Chromium writes) into rows of pixels.
std::vector<std::vector<std::uint32_t>> read_png(const std::string& bytes) {
  auto be32 = [&](size_t i) {
    return (std::uint32_t(std::uint8_t(bytes[i])) << 24) | (std::uint32_t(std::uint8_t(bytes[i + 1])) << 16) |
           (std::uint32_t(std::uint8_t(bytes[i + 2])) << 8) | std::uint32_t(std::uint8_t(bytes[i + 3]));
  };
  if (bytes.size() < 33 || bytes.compare(1, 3, "PNG") != 0) return {};
  const std::uint32_t w = be32(16), h = be32(20);
  const int depth = bytes[24], type = bytes[25], interlace = bytes[28];
  if (depth != 8 || (type != 2 && type != 6) || interlace != 0 || w == 0 || h == 0 || w > 10000 || h > 10000) return {};
  const size_t bpp = type == 6 ? 4 : 3;
  std::string idat;
  for (size_t i = 8; i + 12 <= bytes.size();) {  // chunks: length, type, data, CRC
    const std::uint32_t len = be32(i);
    if (i + 12 + len > bytes.size()) return {};
    if (bytes.compare(i + 4, 4, "IDAT") == 0) idat += bytes.substr(i + 8, len);
    i += 12 + len;
  }
  const size_t stride = w * bpp;
  std::vector<unsigned char> raw((stride + 1) * h);
  uLongf n = raw.size();
  if (uncompress(raw.data(), &n, reinterpret_cast<const Bytef*>(idat.data()), idat.size()) != Z_OK || n != raw.size())
    return {};
  std::vector<unsigned char> prev(stride, 0), cur(stride);
  std::vector<std::vector<std::uint32_t>> img(h, std::vector<std::uint32_t>(w));
  for (std::uint32_t r = 0; r < h; ++r) {
    const unsigned char f = raw[r * (stride + 1)];
    const unsigned char* in = &raw[r * (stride + 1) + 1];
    for (size_t i = 0; i < stride; ++i) {
      const int a = i >= bpp ? cur[i - bpp] : 0, b = prev[i], c = i >= bpp ? prev[i - bpp] : 0;
      int pred = 0;
      if (f == 1) pred = a;
      else if (f == 2) pred = b;
      else if (f == 3) pred = (a + b) / 2;
      else if (f == 4) {  // Paeth
        const int p = a + b - c, pa = std::abs(p - a), pb = std::abs(p - b), pc = std::abs(p - c);
        pred = pa <= pb && pa <= pc ? a : pb <= pc ? b : c;
      }
      cur[i] = static_cast<unsigned char>(in[i] + pred);
    }
    for (std::uint32_t x = 0; x < w; ++x)
      img[r][x] = (std::uint32_t(cur[x * bpp]) << 16) | (std::uint32_t(cur[x * bpp + 1]) << 8) | cur[x * bpp + 2];
    prev = cur;
  }
  return img;
}

TEST_F(Browser, ScreenshotIsNotBlank) {
  ASSERT_EQ(run_rdyn({"animate", "fourbar", "--duration", "0.5", "--out", (dir_ / "anim").string()}, dir_).status, 0);
  auto argv = chromium("--screenshot=" + (dir_ / "shot.png").string());
  argv.insert(argv.end() - 1, "--window-size=800,600");
  argv.back() = "--screenshot=" + (dir_ / "shot.png").string();
  argv.push_back("file://" + (dir_ / "anim" / "animation.html").string() + "#t=0.25");
  const auto r = run_argv(argv, dir_);
  ASSERT_EQ(r.status, 0) << r.err.substr(0, 500);
  const auto img = read_png(test::slurp(dir_ / "shot.png"));
  ASSERT_EQ(img.size(), 600u);
  // Count the colours and the dark pixels (the bodies' strokes): a page that drew nothing is
  // white with the controls only, a broken one a single colour.
  std::set<std::uint32_t> colours;
  size_t dark = 0;
  for (const auto& row : img)
    for (auto px : row) {
      colours.insert(px);
      const int lum = ((px >> 16) & 255) + ((px >> 8) & 255) + (px & 255);
      dark += lum < 3 * 96;
    }
  EXPECT_GT(colours.size(), 20u);
  EXPECT_GT(dark, 500u);
}

TEST_F(Browser, InspectSvgDrawsEveryJointAndTheRange) {
  const fs::path svg = dir_ / "fourbar-rocker.svg";
  const auto r = run_rdyn({"inspect", "fourbar-rocker", "--svg", svg.string()}, dir_);
  ASSERT_EQ(r.status, 0) << r.err;
  const std::string text = test::slurp(svg);
  const auto s = models::load_scene("fourbar-rocker", {});
  const auto joints = positions(text, "data-joint");
  EXPECT_EQ(joints.size(), s.joints.size());
  EXPECT_NE(text.find("dead points at"), std::string::npos);
  // Chromium parses it (an SVG document) and keeps every joint.
  const std::string dom = dump_dom(svg, 0);
  EXPECT_EQ(positions(dom, "data-joint").size(), s.joints.size());
  // Not replaced when foreign; replaced when rdyn's own.
  test::RdynRun again = run_rdyn({"inspect", "fourbar-rocker", "--svg", svg.string()}, dir_);
  EXPECT_EQ(again.status, 0) << again.err;
  const fs::path foreign = dir_ / "mine.svg";
  { std::ofstream(foreign) << "<svg>my drawing</svg>"; }
  EXPECT_EQ(run_rdyn({"inspect", "fourbar-rocker", "--svg", foreign.string()}, dir_).status, 2);
  EXPECT_EQ(test::slurp(foreign), "<svg>my drawing</svg>");
}

TEST_F(Browser, BadArgumentsExitTwoAndWriteNothing) {
  EXPECT_EQ(run_rdyn({"animate", "fourbar", "--trace", "crank.nowhere", "--out", "a"}, dir_).status, 2);
  EXPECT_EQ(run_rdyn({"animate", "fourbar", "--duration", "-1", "--out", "a"}, dir_).status, 2);
  EXPECT_EQ(run_rdyn({"animate", "fourbar", "--dt-out", "0", "--out", "a"}, dir_).status, 2);
  EXPECT_EQ(run_rdyn({"animate", "fourbar", "--model", "other", "--out", "a"}, dir_).status, 2);
  EXPECT_FALSE(fs::exists(dir_ / "a"));
}

}  // namespace
}  // namespace rdyn::validate
