#include "sim/material.h"

#include <unistd.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "sim/test_expect_throw.h"

namespace clothwind::sim {
namespace {

namespace fs = std::filesystem;

Eigen::Matrix<double, 6, 4> Table6x4(double base) {
  Eigen::Matrix<double, 6, 4> s;
  for (int r = 0; r < 6; ++r) s.row(r) << base * (1 + r), base * 0.2, base * (2 + r), base * 0.5;
  return s;
}

Eigen::Matrix<double, 3, 5> Table3x5() {
  Eigen::Matrix<double, 3, 5> b;
  b << 1, 2, 3, 4, 5, 10, 20, 30, 40, 50, 100, 200, 300, 400, 500;
  return b * 1e-6;
}

TEST(MaterialTest, UnstrainedStiffnessIsTwiceRowZeroAndMultipliersScale) {
  const Material m = MakeMaterial(0.2, Table6x4(10), Table3x5());
  // At a grid point under slight compression the principal stretch is below 1: the sample is
  // row 0, doubled as ArcSim does. (At G = 0 itself ArcSim's grid interpolates 10 % of the way to
  // the stretched row, since G = 0 lies between samples.)
  const Eigen::Matrix2d Gc = Eigen::Vector2d(-1.0 / 60, -1.0 / 60).asDiagonal();
  const Eigen::Vector4d k0 = m.StretchingStiffness(Gc);
  EXPECT_LT((k0 - 2 * Table6x4(10).row(0).transpose()).norm(), 1e-9);
  MaterialMultipliers mult;
  mult.stretching = 3;
  mult.bending = 5;
  mult.density = 7;
  mult.thicken = 2;
  const Material s = MakeMaterial(0.2, Table6x4(10), Table3x5(), mult);
  EXPECT_DOUBLE_EQ(s.density, 0.2 * 7 * 2);
  EXPECT_LT((s.StretchingStiffness(Gc) - 6 * k0).norm(), 1e-9);
  EXPECT_LT((s.StretchingStiffness(Eigen::Matrix2d::Zero()) - 6 * m.StretchingStiffness(Eigen::Matrix2d::Zero())).norm(), 1e-9);
  const Eigen::Vector2d along_u(1, 0);
  EXPECT_NEAR(s.BendingStiffness(0, along_u), 10 * m.BendingStiffness(0, along_u), 1e-18);
}

TEST(MaterialTest, StiffnessGrowsWithStretchTowardsDirectionalRow) {
  const Material m = MakeMaterial(0.2, Table6x4(10), Table3x5());
  // Stretch 1 + 1/6 along u (G00 = ((7/6)^2 - 1)/2, on a grid-aligned direction): row 1 (0 deg).
  const double s = 7.0 / 6.0;
  Eigen::Matrix2d G = Eigen::Matrix2d::Zero();
  G(0, 0) = 0.5 * (s * s - 1);
  const Eigen::Vector4d k = m.StretchingStiffness(G);
  const Eigen::Vector4d row1 = 2 * Table6x4(10).row(1).transpose();
  EXPECT_LT((k - row1).norm(), 0.05 * row1.norm()) << k.transpose();
  // Along v: row 5 (90 degrees), and along the diagonal row 3 (45 degrees), each that row and not
  // a neighbour (rows 1 apart differ by 10 in k0 here; "stiffer than along u" passed a direction
  // read as 45 degrees at 90).
  Eigen::Matrix2d Gv = Eigen::Matrix2d::Zero();
  Gv(1, 1) = G(0, 0);
  const Eigen::Vector4d row5 = 2 * Table6x4(10).row(5).transpose();
  EXPECT_LT((m.StretchingStiffness(Gv) - row5).norm(), 0.05 * row5.norm()) << m.StretchingStiffness(Gv).transpose();
  const Eigen::Matrix2d Gd = Eigen::Matrix2d::Constant(0.5 * G(0, 0));  // (s^2 - 1) / 2 along (1, 1) / sqrt 2
  const Eigen::Vector4d row3 = 2 * Table6x4(10).row(3).transpose();
  EXPECT_LT((m.StretchingStiffness(Gd) - row3).norm(), 0.05 * row3.norm()) << m.StretchingStiffness(Gd).transpose();
  // Monotone in between.
  Eigen::Matrix2d Gh = 0.5 * G;
  EXPECT_GT(m.StretchingStiffness(Gh)[0], m.StretchingStiffness(Eigen::Matrix2d::Zero())[0]);
  EXPECT_LT(m.StretchingStiffness(Gh)[0], k[0]);
}

TEST(MaterialTest, BendingInterpolatesDirectionAndCurvature) {
  const Material m = MakeMaterial(0.2, Table6x4(10), Table3x5());
  const auto b = Table3x5();
  EXPECT_NEAR(m.BendingStiffness(0, {1, 0}), b(0, 0), 1e-15);
  EXPECT_NEAR(m.BendingStiffness(0, {0, 1}), b(2, 0), 1e-15);
  EXPECT_NEAR(m.BendingStiffness(0, {-1, -1}), b(1, 0), 1e-15);     // 45 degrees either way
  EXPECT_NEAR(m.BendingStiffness(20, {1, 0}), b(0, 2), 1e-15);       // curvature 20 1/m: column 2
  EXPECT_NEAR(m.BendingStiffness(-20, {1, 0}), b(0, 2), 1e-15);      // magnitude
  EXPECT_NEAR(m.BendingStiffness(15, {0, -1}), 0.5 * (b(2, 1) + b(2, 2)), 1e-15);
  EXPECT_NEAR(m.BendingStiffness(1e3, {1, 0}), b(0, 4), 1e-15);      // clamped beyond 40 1/m
}

// The files WriteText wrote, removed when the test program ends (each run left 16 in /tmp).
struct WrittenFiles {
  std::vector<std::string> paths;
  ~WrittenFiles() {
    for (const std::string& p : paths) std::remove(p.c_str());
  }
};
WrittenFiles written_files;

std::string WriteText(const std::string& name, const std::string& text) {
  const std::string path = ::testing::TempDir() + "/clothwind_material_test_" + std::to_string(::getpid()) + "_" + name;
  std::ofstream(path) << text;
  written_files.paths.push_back(path);
  return path;
}

TEST(MaterialTest, BadFilesFailNamingFileAndField) {
  ExpectThrowContaining([] { LoadArcSimMaterial("/nonexistent/cloth.json"); }, "/nonexistent/cloth.json: cannot open");
  const std::string rows = "[[1,2,3,4],[1,2,3,4],[1,2,3,4],[1,2,3,4],[1,2,3,4],[1,2,3,4]]";
  const std::string bend = "[[1,2,3,4,5],[1,2,3,4,5],[1,2,3,4,5]]";
  const std::string no_density = WriteText("nodensity.json", "{\"stretching\": " + rows + ", \"bending\": " + bend + "}");
  ExpectThrowContaining([&] { LoadArcSimMaterial(no_density); }, no_density + ": missing field 'density'");
  const std::string short_rows = WriteText("short.json", "{\"density\": 0.1, \"stretching\": [[1,2,3,4]], \"bending\": " + bend + "}");
  ExpectThrowContaining([&] { LoadArcSimMaterial(short_rows); }, "field 'stretching' must be an array of 6 rows");
  const std::string bad_value = WriteText("badvalue.json", "{\"density\": 0.1, \"stretching\": " + rows +
                                                               ", \"bending\": [[1,2,3,4,5],[1,\"x\",3,4,5],[1,2,3,4,5]]}");
  ExpectThrowContaining([&] { LoadArcSimMaterial(bad_value); }, "field 'bending[1][1]' must be a number");
  const std::string negative = WriteText("negdensity.json", "{\"density\": -1, \"stretching\": " + rows + ", \"bending\": " + bend + "}");
  ExpectThrowContaining([&] { LoadArcSimMaterial(negative); }, "field 'density' must be > 0");
  const std::string flat = WriteText("flatbending.json", "{\"density\": 0.1, \"stretching\": " + rows +
                                                          ", \"bending\": [[0,0,0,0,0],[0,0,0,0,0],[0,0,0,0,0]]}");
  ExpectThrowContaining([&] { LoadArcSimMaterial(flat); }, flat + ": field 'bending' must hold stiffnesses > 0");
  std::string zero_rows = "[";
  for (int r = 0; r < 6; ++r) zero_rows += std::string(r ? "," : "") + "[0,0,0,0]";
  zero_rows += "]";
  const std::string slack = WriteText("slack.json", "{\"density\": 0.1, \"stretching\": " + zero_rows +
                                                        ", \"bending\": " + bend + "}");
  ExpectThrowContaining([&] { LoadArcSimMaterial(slack); }, slack + ": field 'stretching' column 0 (warp) has no stiffness > 0");
  const std::string broken = WriteText("broken.json", "{\"density\": ");
  ExpectThrowContaining([&] { LoadArcSimMaterial(broken); }, broken + ": not valid JSON");
  const std::string commented = WriteText("commented.json", "// a comment like paper.json's\n{\"density\": 0.1, /* x */ \"stretching\": " +
                                                                rows + ", \"bending\": " + bend + "}");
  EXPECT_NO_THROW(LoadArcSimMaterial(commented));
  MaterialMultipliers bad;
  bad.thicken = 0;
  ExpectThrowContaining([&] { LoadArcSimMaterial(commented, bad); }, "thicken must be finite and > 0");
  // A density given twice ran with the second (100 times heavier), without a word.
  const std::string twice = WriteText("twice.json", "{\"density\": 0.135, \"stretching\": " + rows +
                                                        ", \"bending\": " + bend + ", \"density\": 13.5}");
  ExpectThrowContaining([&] { LoadArcSimMaterial(twice); }, twice + ": key \"density\" is given twice");
  const std::string unclosed = WriteText("unclosed.json", "{\"density\": 0.1 /* never closed\n}");
  ExpectThrowContaining([&] { LoadArcSimMaterial(unclosed); }, unclosed + ": ");
}

TEST(MaterialTest, AreaWeightsFarBeyondAnyClothAreRefusedNamingFileAndField) {
  // A density of 1e200 kg/m^2 (a typo, a hostile file) loaded, and the simulation overflowed and
  // silently never moved the cloth. At most 1000 kg/m^2, from the file and after multipliers.
  const std::string rows = "[[1,2,3,4],[1,2,3,4],[1,2,3,4],[1,2,3,4],[1,2,3,4],[1,2,3,4]]";
  const std::string bend = "[[1,2,3,4,5],[1,2,3,4,5],[1,2,3,4,5]]";
  auto file = [&](const std::string& name, const std::string& density) {
    return WriteText(name, "{\"density\": " + density + ", \"stretching\": " + rows + ", \"bending\": " + bend + "}");
  };
  const std::string huge = file("huge.json", "1e200");
  ExpectThrowContaining([&] { LoadArcSimMaterial(huge); },
                        huge + ": field 'density' is 1e+200 kg/m^2, expected at most 1000");
  EXPECT_NO_THROW(LoadArcSimMaterial(file("heaviest.json", "1000")));
  MaterialMultipliers thick;
  thick.thicken = 1e4;  // x 0.2 = 2000 kg/m^2
  const std::string light = file("light.json", "0.2");
  ExpectThrowContaining([&] { LoadArcSimMaterial(light, thick); }, light + ": material: area weight after multipliers");
  thick.thicken = 5e3;  // 1000 kg/m^2: the limit itself
  EXPECT_NO_THROW(LoadArcSimMaterial(light, thick));
  // Tables whose product with the multipliers overflows: refused, not a non-finite force later.
  MaterialMultipliers stiff;
  stiff.stretching = 1e307;  // x 70 N/m
  ExpectThrowContaining([&] { MakeMaterial(0.2, Table6x4(10), Table3x5(), stiff); }, "stretching table x stretching_mult");
  MaterialMultipliers rigid;
  rigid.bending = 1e308;  // x thicken 1e5 x 5e-4 N m (and the weight kept: density_mult 1e-5)
  rigid.thicken = 1e5;
  rigid.density = 1e-5;
  ExpectThrowContaining([&] { MakeMaterial(0.2, Table6x4(10), Table3x5(), rigid); }, "bending table x bending_mult");
}

TEST(MaterialTest, TableEntriesFarBeyondAnyMaterialAreRefusedNamingTheEntry) {
  // A stretching entry of 1e30 loaded, and the simulation "blew up at t = 0.0100 s (step 2)",
  // naming neither the file nor the entry. Refused past 1e9 (stretching) and 1e3 N m (bending);
  // the bounds themselves load.
  auto file = [&](const std::string& name, const std::string& first_stretching, const std::string& first_bending) {
    return WriteText(name, "{\"density\": 0.2, \"stretching\": [[" + first_stretching +
                               ",2,3,4],[1,2,3,4],[1,2,3,4],[1,2,3,4],[1,2,3,4],[1,2,3,4]], \"bending\": [[1,2,3,4,5],[1,2," +
                               first_bending + ",4,5],[1,2,3,4,5]]}");
  };
  const std::string stiff = file("stiff.json", "1e30", "3");
  ExpectThrowContaining([&] { LoadArcSimMaterial(stiff); },
                        stiff + ": field 'stretching[0][0]' is 1e+30, expected at most 1e+09 in magnitude");
  const std::string negative = file("negstiff.json", "-2e9", "3");
  ExpectThrowContaining([&] { LoadArcSimMaterial(negative); }, negative + ": field 'stretching[0][0]' is -2e+09");
  const std::string rigid = file("rigid.json", "1", "1e4");
  ExpectThrowContaining([&] { LoadArcSimMaterial(rigid); },
                        rigid + ": field 'bending[1][2]' is 10000, expected at most 1000 N m in magnitude");
  EXPECT_NO_THROW(LoadArcSimMaterial(file("bounds.json", "1e9", "1000")));
}

TEST(MaterialTest, ANotANumberCurvatureGivesANotANumberStiffness) {
  // Cast to a table index, a NaN curvature was undefined behaviour (a scene whose repulsion
  // thickness was 1e200 crashed there); a NaN stiffness makes a non-finite force the step reports.
  const std::array<double, 5> row = {1, 2, 3, 4, 5};
  EXPECT_TRUE(std::isnan(Material::BendingStiffnessFromRow(std::nan(""), row)));
  EXPECT_EQ(Material::BendingStiffnessFromRow(std::numeric_limits<double>::infinity(), row), 5);
  EXPECT_EQ(Material::BendingStiffnessFromRow(-std::numeric_limits<double>::infinity(), row), 5);
}

TEST(MaterialTest, IgnoredKeysAreNamed) {
  // A misspelt key ("bendng") or one of ArcSim's that is not simulated here loads with a warning
  // naming the file and key; the three read keys warn of nothing.
  const std::string rows = "[[1,2,3,4],[1,2,3,4],[1,2,3,4],[1,2,3,4],[1,2,3,4],[1,2,3,4]]";
  const std::string bend = "[[1,2,3,4,5],[1,2,3,4,5],[1,2,3,4,5]]";
  const std::string plain = WriteText("plain.json", "{\"density\": 0.1, \"stretching\": " + rows + ", \"bending\": " + bend + "}");
  EXPECT_TRUE(ArcSimMaterialWarnings(plain).empty());
  const std::string extra = WriteText("extra.json", "{\"density\": 0.1, \"stretching\": " + rows + ", \"bending\": " + bend +
                                                        ", \"bendng\": 2, \"yield_curv\": 3, \"damping\": 0.1}");
  EXPECT_NO_THROW(LoadArcSimMaterial(extra));
  const std::vector<std::string> w = ArcSimMaterialWarnings(extra);
  ASSERT_EQ(w.size(), 3u);
  EXPECT_EQ(w[0], extra + ": key 'bendng' is not a material field (density, stretching, bending), ignored");
  // damping is simulated, from the scene's material entry: the warning says where it goes.
  EXPECT_EQ(w[1], extra + ": key 'damping' belongs in the scene's materials[] entry (ArcSim ignores it in a "
                          "material file too), ignored here");
  EXPECT_EQ(w[2], extra + ": key 'yield_curv' belongs in the scene's materials[] entry, and plasticity is not "
                          "simulated here, ignored");
}

TEST(MaterialTest, EveryArcSimMaterialLoadsWithSaneValues) {
  const char* shared = std::getenv("CLOTHWIND_SHARED_DIR");
  if (!shared || !fs::is_directory(fs::path(shared) / "arcsim" / "materials"))
    GTEST_SKIP() << "CLOTHWIND_SHARED_DIR/arcsim/materials not available";
  int count = 0;
  for (const auto& entry : fs::directory_iterator(fs::path(shared) / "arcsim" / "materials")) {
    if (entry.path().extension() != ".json") continue;
    SCOPED_TRACE(entry.path().string());
    const Material m = LoadArcSimMaterial(entry.path().string());
    ++count;
    EXPECT_GT(m.density, 0.01);
    EXPECT_LT(m.density, 2.0);  // kg/m^2: fabrics ~0.1-0.5, aluminium foil/paper in range
    const Eigen::Vector4d k0 = m.StretchingStiffness(Eigen::Matrix2d::Zero());
    EXPECT_TRUE(k0.allFinite());
    EXPECT_TRUE((k0.array() >= 0).all());
    // Every material resists uniaxial stretch along both material axes.
    Eigen::Matrix2d G = Eigen::Matrix2d::Zero();
    G(0, 0) = 0.05;
    EXPECT_GT(m.StretchingStiffness(G)[0], 0);
    G.setZero();
    G(1, 1) = 0.05;
    EXPECT_GT(m.StretchingStiffness(G)[2], 0);
    for (double curv : {0.0, 5.0, 50.0})
      for (const Eigen::Vector2d& du : {Eigen::Vector2d(1, 0), Eigen::Vector2d(1, 1), Eigen::Vector2d(0, 1)}) {
        const double kb = m.BendingStiffness(curv, du);
        EXPECT_GE(kb, 0);
        EXPECT_LT(kb, 1e-2);  // N m: cloth ~1e-5, paper 4e-4
      }
  }
  EXPECT_GE(count, 10);
  // camel-ponte-roma with thicken 2 (the flag scene): twice the density.
  const Material flag = LoadArcSimMaterial((fs::path(shared) / "arcsim/materials/camel-ponte-roma.json").string(),
                                           MaterialMultipliers{1, 1, 1, 2, 0});
  EXPECT_NEAR(flag.density, 2 * 0.284, 1e-12);
}

}  // namespace
}  // namespace clothwind::sim
