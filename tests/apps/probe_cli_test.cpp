// foxi probe and foxi plot, end to end: a linear field probed at random points reads back the analytic
// value to rounding, in a tet that really holds the point (checked here by its own barycentric
// coordinates) and with the region of that tet; a cell field reads back its tet's value; points
// outside say so; the plot's CSV of a linear field equals the analytic line, with gaps (nan) outside;
// bad options exit 2 and bad files exit 3.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "foxi/model/mesh_io.hpp"
#include "foxi/viz/chart.hpp"
#include "foxi/viz/png.hpp"
#include "test_util.hpp"
#include "viz/mesh_factory.hpp"

namespace foxi {
namespace {

double linear(const double* p) { return 300 + 10 * p[0] + 3 * p[1] - 7 * p[2]; }

// The barycentric coordinates of p in tet t, computed directly (Cramer's rule on volumes).
void bary_of(const Mesh& m, std::size_t t, const double* p, double out[4]) {
  auto vol = [](const double* a, const double* b, const double* c, const double* d) {
    double u[3], v[3], w[3];
    for (int k = 0; k < 3; ++k) u[k] = b[k] - a[k], v[k] = c[k] - a[k], w[k] = d[k] - a[k];
    return u[0] * (v[1] * w[2] - v[2] * w[1]) - u[1] * (v[0] * w[2] - v[2] * w[0]) +
           u[2] * (v[0] * w[1] - v[1] * w[0]);
  };
  const double* c[4];
  for (int j = 0; j < 4; ++j) c[j] = &m.xyz[3 * std::size_t(m.tet[4 * t + j])];
  const double total = vol(c[0], c[1], c[2], c[3]);
  for (int j = 0; j < 4; ++j) {
    const double* q[4] = {c[0], c[1], c[2], c[3]};
    q[j] = p;
    out[j] = vol(q[0], q[1], q[2], q[3]) / total;
  }
}

class ProbeCli : public ::testing::Test {
 protected:
  void SetUp() override {
    Mesh m = test::grid_mesh(8, 4, 2, 1, 1, 1, 6);
    // Interior nodes moved a little, so the tets are not a regular pattern.
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> jitter(-0.12, 0.12);
    for (std::size_t n = 0; n < m.node_count(); ++n) {
      double* p = &m.xyz[3 * n];
      if (p[0] > 0 && p[0] < 8 && p[1] > 0 && p[1] < 4 && p[2] > 0 && p[2] < 2)
        for (int k = 0; k < 3; ++k) p[k] += jitter(rng);
    }
    test::regions_along_x(m, 3, 6);
    m.regions = {{1, "copper", kNone}, {2, "solder", kNone}, {3, "", kNone}};
    Field t{"temperature", FieldLocation::node, 1, "K", {}, {}};
    Field u{"displacement", FieldLocation::node, 3, "m", {}, {}};
    for (std::size_t n = 0; n < m.node_count(); ++n) {
      const double* p = &m.xyz[3 * n];
      t.values.push_back(linear(p));
      for (double v : {1e-6 * p[1], -2e-6 * p[0], 0.5e-6 * p[2]}) u.values.push_back(v);
    }
    Field s{"stress", FieldLocation::cell, 6, "Pa", {}, {}};
    for (std::size_t e = 0; e < m.tet_count(); ++e)
      for (double v : {1e3 * double(e + 1), 0.0, 0.0, 0.0, 0.0, 0.0}) s.values.push_back(v);
    m.fields = {t, u, s};
    mesh_ = m;
    path_ = dir_ / "result.vtu";
    write_mesh(m, path_);
  }
  int foxi(const std::string& args, std::string* out = nullptr) {
    const int status = test::run("'" + test::cli_path() + "' " + args, dir_ / "log.txt");
    if (out) *out = test::read_text(dir_ / "log.txt");
    return status;
  }
  std::string file() const { return "'" + path_.string() + "'"; }
  // The lines of `log` that start with "point ".
  static std::vector<std::string> point_lines(const std::string& log) {
    std::vector<std::string> out;
    std::istringstream in(log);
    for (std::string line; std::getline(in, line);)
      if (line.rfind("point ", 0) == 0) out.push_back(line);
    return out;
  }
  test::TempDir dir_;
  Mesh mesh_;
  std::filesystem::path path_;
};

TEST_F(ProbeCli, LinearFieldAtRandomPointsIsTheAnalyticValueInAHoldingTet) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> ux(0.01, 7.99), uy(0.01, 3.99), uz(0.01, 1.99);
  std::vector<std::array<double, 3>> pts;
  std::string args = "probe " + file() + " --field temperature";
  char buf[128];
  for (int i = 0; i < 40; ++i) {
    pts.push_back({ux(rng), uy(rng), uz(rng)});
    std::snprintf(buf, sizeof buf, " --at %.17g,%.17g,%.17g", pts.back()[0], pts.back()[1], pts.back()[2]);
    args += buf;
  }
  std::string log;
  ASSERT_EQ(foxi(args, &log), 0) << log;
  const std::vector<std::string> lines = point_lines(log);
  ASSERT_EQ(lines.size(), pts.size()) << log;
  for (std::size_t i = 0; i < pts.size(); ++i) {
    unsigned tet = 0;
    int region = 0;
    double value = 0;
    const std::size_t at = lines[i].find(": tet ");
    ASSERT_NE(at, std::string::npos) << lines[i];
    ASSERT_EQ(std::sscanf(lines[i].c_str() + at, ": tet %u, region %d", &tet, &region), 2) << lines[i];
    const std::size_t eq = lines[i].find("temperature = ");
    ASSERT_NE(eq, std::string::npos) << lines[i];
    ASSERT_EQ(std::sscanf(lines[i].c_str() + eq, "temperature = %lf K", &value), 1) << lines[i];
    ASSERT_LT(tet, mesh_.tet_count());
    double b[4];
    bary_of(mesh_, tet, pts[i].data(), b);
    for (double x : b) EXPECT_GE(x, -1e-9) << "tet " << tet << " does not hold point " << i;
    EXPECT_EQ(region, mesh_.tet_region[tet]) << lines[i];
    EXPECT_NEAR(value, linear(pts[i].data()), 1e-9 * 400) << lines[i];
    // The display unit: °C from K.
    double celsius = 0;
    const std::size_t paren = lines[i].find(" (", eq);
    ASSERT_NE(paren, std::string::npos) << lines[i];
    ASSERT_EQ(std::sscanf(lines[i].c_str() + paren, " (%lf", &celsius), 1) << lines[i];
    EXPECT_NEAR(celsius, linear(pts[i].data()) - 273.15, 1e-3) << lines[i];
    EXPECT_NE(lines[i].find("°C"), std::string::npos) << lines[i];
  }
  // Region names: region 1 is "copper".
  ASSERT_EQ(foxi("probe " + file() + " --field temperature --at 1.5,2,1", &log), 0) << log;
  EXPECT_NE(log.find("region 1 (copper)"), std::string::npos) << log;
}

TEST_F(ProbeCli, VectorComponentAndMagnitude) {
  const double p[3] = {2.3, 1.7, 0.9};
  std::string log;
  ASSERT_EQ(foxi("probe " + file() + " --field displacement:y --at 2.3,1.7,0.9", &log), 0) << log;
  double v = 0;
  const std::size_t eq = log.find(" = ");
  ASSERT_NE(eq, std::string::npos) << log;
  ASSERT_EQ(std::sscanf(log.c_str() + eq, " = %lf m", &v), 1) << log;
  EXPECT_NEAR(v, -2e-6 * p[0], 1e-18) << log;
  // The magnitude of the interpolated (linear, so exact) vector.
  ASSERT_EQ(foxi("probe " + file() + " --field displacement --at 2.3,1.7,0.9", &log), 0) << log;
  const std::size_t eq2 = log.find(" = ");
  ASSERT_NE(eq2, std::string::npos) << log;
  ASSERT_EQ(std::sscanf(log.c_str() + eq2, " = %lf m", &v), 1) << log;
  EXPECT_NEAR(v, std::hypot(1e-6 * p[1], -2e-6 * p[0], 0.5e-6 * p[2]), 1e-18) << log;
  EXPECT_NE(log.find("µm"), std::string::npos) << log;
}

TEST_F(ProbeCli, CellFieldIsTheHoldingTetsValue) {
  std::string log;
  ASSERT_EQ(foxi("probe " + file() + " --field stress:xx --at 4.2,2.1,1.3 --at 7.1,0.4,0.2", &log), 0) << log;
  const std::vector<std::string> lines = point_lines(log);
  ASSERT_EQ(lines.size(), 2u) << log;
  const double pts[2][3] = {{4.2, 2.1, 1.3}, {7.1, 0.4, 0.2}};
  for (int i = 0; i < 2; ++i) {
    unsigned tet = 0;
    double v = 0;
    const std::size_t at = lines[i].find(": tet ");
    ASSERT_NE(at, std::string::npos) << lines[i];
    ASSERT_EQ(std::sscanf(lines[i].c_str() + at, ": tet %u", &tet), 1) << lines[i];
    const std::size_t eq = lines[i].find(" = ");
    ASSERT_EQ(std::sscanf(lines[i].c_str() + eq, " = %lf Pa", &v), 1) << lines[i];
    ASSERT_LT(tet, mesh_.tet_count());
    double b[4];
    bary_of(mesh_, tet, pts[i], b);
    for (double x : b) EXPECT_GE(x, -1e-9) << lines[i];
    EXPECT_EQ(v, 1e3 * double(tet + 1)) << lines[i];  // the file's value of that tet, exactly
  }
}

TEST_F(ProbeCli, PointsOutsideTheMesh) {
  std::string log;
  // One inside, one outside: both reported, exit 0.
  ASSERT_EQ(foxi("probe " + file() + " --field temperature --at 1,1,1 --at 9,1,1", &log), 0) << log;
  const std::vector<std::string> lines = point_lines(log);
  ASSERT_EQ(lines.size(), 2u) << log;
  EXPECT_NE(lines[0].find("temperature = "), std::string::npos) << log;
  EXPECT_NE(lines[1].find("outside the mesh"), std::string::npos) << log;
  // None inside: exit 3, saying so.
  EXPECT_EQ(foxi("probe " + file() + " --field temperature --at 9,1,1 --at 1,1,-0.5", &log), 3) << log;
  EXPECT_NE(log.find("no point lies in the mesh"), std::string::npos) << log;
}

TEST_F(ProbeCli, BadOptionsExit2BadFilesExit3) {
  std::string log;
  EXPECT_EQ(foxi("probe --help", &log), 0) << log;
  EXPECT_NE(log.find("foxi probe RESULT"), std::string::npos) << log;
  EXPECT_EQ(foxi("plot --help", &log), 0) << log;
  EXPECT_NE(log.find("foxi plot RESULT"), std::string::npos) << log;
  EXPECT_EQ(foxi("probe " + file() + " --at 1,1,1", &log), 2) << log;                      // no --field
  EXPECT_EQ(foxi("probe " + file() + " --field temperature", &log), 2) << log;             // no --at
  EXPECT_EQ(foxi("probe " + file() + " --field temperature --at 1,1", &log), 2) << log;    // two numbers
  EXPECT_EQ(foxi("probe " + file() + " --field temperature --at 1,x,1", &log), 2) << log;  // not a number
  EXPECT_EQ(foxi("probe " + file() + " --field pressure --at 1,1,1", &log), 2) << log;     // no such field
  EXPECT_NE(log.find("temperature"), std::string::npos) << log;  // says what there is
  EXPECT_EQ(foxi("probe " + file() + " --field temperature:q --at 1,1,1", &log), 2)
      << log;  // no such component
  EXPECT_EQ(foxi("probe " + file() + " --field temperature --at 1,1,1 --step 3", &log), 2) << log;
  EXPECT_EQ(foxi("probe " + file() + " --field temperature --at 1,1,1 --bogus", &log), 2) << log;
  const std::string line = " --field temperature --line 0,0,0:8,4,2 -o '" + (dir_ / "p.csv").string() + "'";
  EXPECT_EQ(
      foxi("plot " + file() + " --field temperature --line 0,0,0 -o '" + (dir_ / "p.csv").string() + "'",
           &log),
      2)
      << log;
  EXPECT_EQ(foxi("plot " + file() + line + " --samples 1", &log), 2) << log;
  EXPECT_EQ(foxi("plot " + file() + " --field temperature --line 0,0,0:8,4,2", &log), 2) << log;  // no -o
  EXPECT_FALSE(std::filesystem::exists(dir_ / "p.csv"));
  // Files: missing, not a mesh.
  EXPECT_EQ(foxi("probe '" + (dir_ / "missing.vtu").string() + "' --field temperature --at 1,1,1", &log), 3)
      << log;
  test::write_text(dir_ / "junk.vtu", "<VTKFile this is not");
  EXPECT_EQ(foxi("probe '" + (dir_ / "junk.vtu").string() + "' --field temperature --at 1,1,1", &log), 3)
      << log;
  EXPECT_NE(log.find("junk.vtu"), std::string::npos) << log;
  EXPECT_EQ(foxi("plot '" + (dir_ / "junk.vtu").string() + "'" + line, &log), 3) << log;
  EXPECT_FALSE(std::filesystem::exists(dir_ / "p.csv"));
}

TEST_F(ProbeCli, PlotCsvOfALinearFieldIsTheAnalyticLineWithGapsOutside) {
  const auto csv = dir_ / "plot.csv";
  std::string log;
  // From outside (x = -1) through the mesh to outside (x = 9): the samples at x < 0 and x > 8 are gaps.
  ASSERT_EQ(foxi("plot " + file() + " --field temperature --line -1,1.3,0.7:9,2.9,1.1 --samples 51 -o '" +
                     csv.string() + "'",
                 &log),
            0)
      << log;
  std::istringstream in(test::read_text(csv));
  std::string header;
  std::getline(in, header);
  EXPECT_EQ(header, "s [m],x [m],y [m],z [m],tet,region,temperature [K]");
  const double a[3] = {-1, 1.3, 0.7}, b[3] = {9, 2.9, 1.1};
  const double length = std::hypot(b[0] - a[0], b[1] - a[1], b[2] - a[2]);
  int rows = 0, gaps = 0;
  for (std::string row; std::getline(in, row); ++rows) {
    std::vector<std::string> col;
    std::stringstream ss(row);
    for (std::string c; std::getline(ss, c, ',');) col.push_back(c);
    if (row.back() == ',') col.push_back("");
    ASSERT_EQ(col.size(), 7u) << row;
    const double s = double(rows) / 50;
    double p[3];
    for (int k = 0; k < 3; ++k) {
      p[k] = a[k] + s * (b[k] - a[k]);
      EXPECT_NEAR(std::stod(col[1 + std::size_t(k)]), p[k], 1e-12) << row;
    }
    EXPECT_NEAR(std::stod(col[0]), s * length, 1e-9) << row;
    const bool outside = p[0] < -1e-12 || p[0] > 8 + 1e-12;
    if (outside) {
      ++gaps;
      EXPECT_EQ(col[4], "") << row;
      EXPECT_EQ(col[6], "nan") << row;
    } else {
      ASSERT_NE(col[4], "") << row;
      double bc[4];
      bary_of(mesh_, std::stoul(col[4]), p, bc);
      for (double x : bc) EXPECT_GE(x, -1e-9) << row;
      EXPECT_EQ(std::stoi(col[5]), mesh_.tet_region[std::stoul(col[4])]) << row;
      EXPECT_NEAR(std::stod(col[6]), linear(p), 1e-9 * 400) << row;
    }
  }
  EXPECT_EQ(rows, 51);
  EXPECT_EQ(gaps, 10);  // x = -1 + 0.2 i: i = 0..4 below 0, i = 46..50 above 8
  EXPECT_NE(log.find("51 samples"), std::string::npos) << log;
  // A line wholly outside: exit 3 and no file.
  EXPECT_EQ(foxi("plot " + file() + " --field temperature --line 9,0,0:10,0,0 -o '" +
                     (dir_ / "none.csv").string() + "'",
                 &log),
            3)
      << log;
  EXPECT_FALSE(std::filesystem::exists(dir_ / "none.csv"));
}

TEST_F(ProbeCli, PlotPngIsALineChartOfTheAskedSize) {
  const auto png = dir_ / "plot.png";
  std::string log;
  ASSERT_EQ(foxi("plot " + file() +
                     " --field temperature --line -1,1.3,0.7:9,2.9,1.1 --samples 201 --size 640x400 -o '" +
                     png.string() + "'",
                 &log),
            0)
      << log;
  const Framebuffer fb = read_png(png);
  ASSERT_EQ(fb.width, 640);
  ASSERT_EQ(fb.height, 400);
  // The series' pixels (the palette's first colour): a rising line (the field grows along it), with
  // the gaps outside the mesh at both ends: it starts right of the first series column a full line
  // would have and ends left of the last.
  const std::uint32_t c = chart_color(0);
  int left = fb.width, right = -1, left_row = 0, right_row = 0;
  std::size_t count = 0;
  for (int y = 0; y < fb.height; ++y)
    for (int x = 0; x < fb.width; ++x)
      if ((fb.rgba[std::size_t(y) * std::size_t(fb.width) + std::size_t(x)] & 0xffffffu) == (c & 0xffffffu)) {
        ++count;
        if (x < left) left = x, left_row = y;
        if (x > right) right = x, right_row = y;
      }
  ASSERT_GT(count, 100u);
  EXPECT_GT(left_row, right_row + 100) << "the line does not rise from " << left << " to " << right;
  EXPECT_GT(right - left, 300);
  EXPECT_NE(log.find("wrote"), std::string::npos) << log;
  // --size is for PNGs only; a chart too small for its labels is a usage error, nothing written.
  EXPECT_EQ(foxi("plot " + file() + " --field temperature --line 0,0,0:8,4,2 --size 640x400 -o '" +
                     (dir_ / "p.csv").string() + "'",
                 &log),
            2)
      << log;
  EXPECT_EQ(foxi("plot " + file() + " --field temperature --line 0,0,0:8,4,2 --size 40x30 -o '" +
                     (dir_ / "small.png").string() + "'",
                 &log),
            2)
      << log;
  EXPECT_FALSE(std::filesystem::exists(dir_ / "small.png"));
}

}  // namespace
}  // namespace foxi
