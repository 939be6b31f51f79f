// `pdvo report` in a browser: two runs of a short street (pdvo with the shipped model, idpp) made into a page,
// opened in headless Chromium. The page loads without errors, its plots have their series, the 3D view draws, and
// the numbers it shows are those of the runs' stats.json and of `pdvo ate`. Labelled browser; it needs Debian's
// chromium (installed by ./run) and saves its screenshots to the build folder (tests/apps/report_*.png).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <regex>
#include <set>

#include "pdvo/common/file_io.h"
#include "pdvo/test/support.h"

namespace pdvo {
namespace {
namespace fs = std::filesystem;

const char* const kChromium = "/usr/bin/chromium";

int Shell(const std::string& command) {
  const int status = std::system(command.c_str());
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

std::string Pdvo(const std::string& args, const test::TempDir& dir) {
  return std::string(PDVO_BINARY) + " " + args + " >> " + (dir / "log.txt") + " 2>&1";
}

// Headless Chromium with software WebGL; `what`: --dump-dom or --screenshot=FILE.
std::string Chromium(const std::string& what, const std::string& url, const std::string& out) {
  return std::string("timeout 120 ") + kChromium +
         " --headless --no-sandbox --enable-unsafe-swiftshader --use-angle=swiftshader --window-size=1280,800 "
         "--virtual-time-budget=10000 " +
         what + " '" + url + "' > " + out + " 2>/dev/null";
}

std::string Attribute(const std::string& html, const std::string& element_regex, const std::string& name) {
  std::smatch m;
  const std::regex re("<" + element_regex + "[^>]*\\s" + name + "=\"([^\"]*)\"");
  return std::regex_search(html, m, re) ? m[1].str() : "<missing>";
}

class Report : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    if (!fs::exists(kChromium)) return;
    dir_ = new test::TempDir();
    const test::TempDir& d = *dir_;
    const std::string model = PDVO_SOURCE_DIR "/models/default/model.yml";
    ok_ = Shell(Pdvo("synth -o " + (d / "street") + " -n 200 --seed 3 -v warning", d)) == 0 &&
          Shell(Pdvo(
              "vo -s " + (d / "street") + " -o " + (d / "pdvo") + " --mode pdvo -m " + model + " --overlay -v warning",
              d)) == 0 &&
          Shell(Pdvo("vo -s " + (d / "street") + " -o " + (d / "idpp") + " --mode idpp --overlay -v warning", d)) == 0;
    for (const char* run : {"pdvo", "idpp"}) {
      ok_ = ok_ && Shell(Pdvo("ate --gt " + (d / "street/groundtruth.txt") + " --est " + (d / run) +
                                  "/trajectory.txt --json " + (d / run) + "/ate.json",
                              d)) == 0;
    }
    ok_ = ok_ && Shell(Pdvo("report " + (d / "pdvo") + " " + (d / "idpp") + " -o " + (d / "report.html"), d)) == 0;
    ok_ = ok_ && Shell(Chromium("--dump-dom", "file://" + (d / "report.html"), d / "dom.html")) == 0;
    for (const char* view : {"page", "map"}) {
      const std::string shot = (fs::current_path() / ("report_" + std::string(view) + ".png")).string();
      const std::string url = "file://" + (d / "report.html") + (std::string(view) == "map" ? "?only=map" : "");
      ok_ = ok_ && Shell(Chromium("--screenshot=" + shot, url, d / "chromium.txt")) == 0;
    }
  }
  static void TearDownTestSuite() { delete dir_; }

  void SetUp() override {
    if (!fs::exists(kChromium)) GTEST_SKIP() << kChromium << " not found (./run installs Debian's chromium)";
    ASSERT_TRUE(ok_) << "making the runs or opening the page failed: " << ReadFile(*dir_ / "log.txt");
  }

  static nlohmann::json Json(const std::string& name) { return nlohmann::json::parse(ReadFile(*dir_ / name)); }

  static inline test::TempDir* dir_ = nullptr;
  static inline bool ok_ = false;
};

TEST_F(Report, LoadsWithoutErrorsAndPlotsEveryRun) {
  const std::string dom = ReadFile(*dir_ / "dom.html");
  EXPECT_EQ(Attribute(dom, "body", "data-ready"), "1") << "the page's script did not run to its end";
  EXPECT_EQ(Attribute(dom, "body", "data-errors"), "0");
  EXPECT_EQ(Attribute(dom, "canvas id=\"fps\"", "data-series"), "2");
  EXPECT_EQ(Attribute(dom, "canvas id=\"fig4\"", "data-series"), "2");
  EXPECT_EQ(Attribute(dom, "canvas id=\"trajectory\"", "data-series"), "3");  // the ground truth and two runs
  EXPECT_EQ(Attribute(dom, "div id=\"map\"", "data-webgl"), "1");
  // pdvo's detections on its keyframes (one picture per keyframe with planes, up to 4) and both runs' views.
  EXPECT_GE(std::stoi(Attribute(dom, "div id=\"stages\"", "data-pictures")), 1);
  EXPECT_GE(std::stoi(Attribute(dom, "div id=\"views\"", "data-pictures")), 2);
  // Offline: nothing is fetched from elsewhere.
  const std::string html = ReadFile(*dir_ / "report.html");
  EXPECT_EQ(html.find("src=\"http"), std::string::npos);
  EXPECT_EQ(html.find("href=\"http"), std::string::npos);
}

TEST_F(Report, ShowsTheNumbersOfTheRuns) {
  const std::string dom = ReadFile(*dir_ / "dom.html");
  std::map<std::pair<int, std::string>, std::pair<double, std::string>> cells;  // (run, key): value, text
  const std::regex cell("data-run=\"(\\d+)\" data-key=\"(\\w+)\" data-value=\"([^\"]*)\">([^<]*)<");
  for (auto it = std::sregex_iterator(dom.begin(), dom.end(), cell); it != std::sregex_iterator(); ++it) {
    cells[{std::stoi((*it)[1].str()), (*it)[2].str()}] = {std::stod((*it)[3].str()), (*it)[4].str()};
  }
  const char* runs[] = {"pdvo", "idpp"};
  for (int r = 0; r < 2; ++r) {
    const nlohmann::json totals = Json(std::string(runs[r]) + "/stats.json")["totals"];
    const nlohmann::json ate = Json(std::string(runs[r]) + "/ate.json")["ate"];
    const std::map<std::string, double> expected = {{"frames", totals["frames"].get<double>()},
                                                    {"planes", totals["planes"].get<double>()},
                                                    {"points_per_plane", totals["points_per_plane"].get<double>()},
                                                    {"mean_plane_area_px", totals["mean_plane_area_px"].get<double>()},
                                                    {"fps", totals["fps"].get<double>()},
                                                    {"ate_m", ate["translation"]["rmse"].get<double>()},
                                                    {"rotation_deg", ate["rotation_deg"]["rmse"].get<double>()}};
    for (const auto& [key, value] : expected) {
      SCOPED_TRACE(std::string(runs[r]) + " " + key);
      ASSERT_TRUE(cells.count({r, key}));
      const auto& [shown, text] = cells.at({r, key});
      EXPECT_NEAR(shown, value, 1e-9 * std::max(1.0, std::abs(value)));
      // The text is the value rounded to the decimals it shows (thousands separated): within half its last digit.
      std::string digits = text;
      digits.erase(std::remove(digits.begin(), digits.end(), ','), digits.end());
      const size_t point = digits.find('.');
      const int decimals = point == std::string::npos ? 0 : static_cast<int>(digits.size() - point - 1);
      EXPECT_NEAR(std::stod(digits), value, 0.5 * std::pow(10.0, -decimals) + 1e-9 * std::abs(value));
    }
  }
  EXPECT_EQ(cells.at({0, "planes_detected"}).first,
            Json("pdvo/stats.json")["totals"]["detections"]["planes_detected"].get<double>());
  EXPECT_FALSE(cells.count({1, "planes_detected"}));  // idpp detects nothing: shown as a dash
}

TEST_F(Report, TheThreeDViewDraws) {
  // The view is of the pdvo run: it has planes to draw only if the run mapped some.
  ASSERT_GT(Json("pdvo/stats.json")["totals"]["planes"].get<int>(), 0) << "the pdvo run mapped no plane";
  const cv::Mat shot = cv::imread((fs::current_path() / "report_map.png").string(), cv::IMREAD_COLOR);
  ASSERT_FALSE(shot.empty());
  // Inside the view, below its title and legend: pixels that are not the white background, and their colours.
  const cv::Mat view = shot(cv::Rect(40, 180, shot.cols - 80, shot.rows - 200));
  int drawn = 0;
  std::set<int> colours;
  for (int y = 0; y < view.rows; ++y) {
    for (int x = 0; x < view.cols; ++x) {
      const cv::Vec3b p = view.at<cv::Vec3b>(y, x);
      if (p[0] > 245 && p[1] > 245 && p[2] > 245) continue;
      ++drawn;
      colours.insert((p[0] / 32) * 64 + (p[1] / 32) * 8 + p[2] / 32);
    }
  }
  EXPECT_GT(drawn, 2000) << "the 3D view is blank";
  EXPECT_GE(colours.size(), 4u) << "points, paths and coloured planes";
}

}  // namespace
}  // namespace pdvo
