#include "sim/mesh.h"

#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <limits>
#include <map>
#include <set>
#include <stdexcept>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "sim/test_expect_throw.h"

namespace clothwind::sim {
namespace {

// The files the tests write, removed when the test program ends (each run left 27 in /tmp).
struct WrittenFiles {
  std::vector<std::string> paths;
  ~WrittenFiles() {
    for (const std::string& p : paths) std::remove(p.c_str());
  }
};
WrittenFiles written_files;

std::string TempPath(const std::string& name) {
  const std::string path = ::testing::TempDir() + "/clothwind_mesh_test_" + std::to_string(::getpid()) + "_" + name;
  written_files.paths.push_back(path);
  return path;
}

std::string WriteText(const std::string& name, const std::string& text) {
  const std::string path = TempPath(name);
  std::ofstream(path) << text;
  return path;
}

// A 3 m x 2 m rectangle of two triangles, like ArcSim's coarse flag in spirit.
Mesh Rectangle() {
  Mesh m;
  m.V.resize(4, 3);
  m.V << 0, 0, 0, 3, 0, 0, 3, 2, 0, 0, 2, 0;
  m.F.resize(2, 3);
  m.F << 0, 1, 2, 0, 2, 3;
  m.U = m.V.leftCols(2);
  return m;
}

// Boundary edges as sets of position pairs (to compare across refinement).
std::multiset<std::pair<int, int>> BoundaryEdges(const Mesh& m) {
  std::map<std::pair<int, int>, int> count;
  for (int f = 0; f < m.F.rows(); ++f)
    for (int c = 0; c < 3; ++c) ++count[std::minmax(m.F(f, c), m.F(f, (c + 1) % 3))];
  std::multiset<std::pair<int, int>> out;
  for (const auto& [e, n] : count)
    if (n == 1) out.insert(e);
  return out;
}

TEST(ObjTest, RoundTripIsExact) {
  Mesh m = RefineMesh(Rectangle(), 0.8);
  m.V.col(2) = m.V.col(0).array().sin() * 0.1;  // non-planar world positions, planar U
  m.U *= 1.0 / 3.0;
  const std::string path = TempPath("roundtrip.obj");
  WriteObj(path, m);
  const Mesh r = ReadObj(path);
  EXPECT_EQ(r.V, m.V);
  EXPECT_EQ(r.U, m.U);
  EXPECT_EQ(r.F, m.F);
  std::ifstream tmp(path + ".tmp");
  EXPECT_FALSE(tmp.good()) << "temporary file left behind";
}

TEST(ObjTest, WithoutTextureCoordinatesRestShapeIsXY) {
  const std::string path = WriteText("novt.obj",
                                     "# comment\nv 0 0 5\nv 1 0 5\nv 1 1 5\nv 0 1 5\n"
                                     "f 1 2 3 4\n");  // a quad: fan-triangulated
  const Mesh m = ReadObj(path);
  ASSERT_EQ(m.F.rows(), 2);
  EXPECT_EQ(m.U(2, 0), 1.0);
  EXPECT_EQ(m.U(2, 1), 1.0);
  EXPECT_DOUBLE_EQ(RestArea(m), 1.0);
}

TEST(ObjTest, ReadsSlashFormsAndNegativeIndices) {
  const std::string path = WriteText("slashes.obj",
                                     "v 0 0 0\nv 2 0 0\nv 0 2 0\nvt 0 0\nvt 1 0\nvt 0 1\n"
                                     "vn 0 0 1\nf 1/1/1 2/2/1 -1/-1/1\n");
  const Mesh m = ReadObj(path);
  EXPECT_EQ(m.U(1, 0), 1.0);  // from vt, not from x
  EXPECT_DOUBLE_EQ(SurfaceArea(m), 2.0);
  EXPECT_DOUBLE_EQ(RestArea(m), 0.5);
}

TEST(ObjTest, BadInputsFailWithFileAndLine) {
  const std::string bad_index = WriteText("bad_index.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 7\n");
  ExpectThrowContaining([&] { ReadObj(bad_index); }, bad_index + ":4: vertex index 7 out of range");
  const std::string bad_number = WriteText("bad_number.obj", "v 0 0 0\nv 1 zero 0\n");
  ExpectThrowContaining([&] { ReadObj(bad_number); }, bad_number + ":2:");
  const std::string nan = WriteText("nan.obj", "v 0 0 0\nv nan 0 0\nv 0 1 0\nf 1 2 3\n");
  ExpectThrowContaining([&] { ReadObj(nan); }, nan + ":2: non-finite");
  const std::string degenerate = WriteText("degenerate.obj", "v 0 0 0\nv 1 0 0\nv 2 0 0\nf 1 2 3\n");
  ExpectThrowContaining([&] { ReadObj(degenerate); }, degenerate + ":4: face is degenerate");
  ExpectThrowContaining([&] { ReadObj(TempPath("does_not_exist.obj")); }, "cannot open");
  const std::string short_face = WriteText("short.obj", "v 0 0 0\nv 1 0 0\nf 1 2\n");
  ExpectThrowContaining([&] { ReadObj(short_face); }, short_face + ":3: a face needs at least 3");
}

TEST(ObjTest, ByteOrderMarkAndAnyLineEndingReadTheSameMesh) {
  // A UTF-8 byte order mark glued itself to the first keyword ("\xEF\xBB\xBFv", skipped: every
  // vertex index was then one off), and a file with old-Mac CR line endings read as one line.
  const std::string lines[] = {"v 0 0 0", "v 1 0 0", "v 1 1 0", "v 0 1 0", "# a unit square", "vt 0 0", "vt 1 0",
                               "vt 1 1", "vt 0 1", "f 1/1 2/2 3/3", "f 1/1 3/3 4/4"};
  auto joined = [&](const std::string& eol) {
    std::string text;
    for (const std::string& l : lines) text += l + eol;
    return text;
  };
  const Mesh reference = ReadObj(WriteText("lf.obj", joined("\n")));
  ASSERT_EQ(reference.V.rows(), 4);
  ASSERT_EQ(reference.F.rows(), 2);
  const std::pair<const char*, std::string> variants[] = {
      {"bom.obj", "\xEF\xBB\xBF" + joined("\n")},
      {"crlf.obj", joined("\r\n")},
      {"cr.obj", joined("\r")},
      {"bom_cr_no_final_eol.obj", "\xEF\xBB\xBF" + joined("\r").substr(0, joined("\r").size() - 1)},
  };
  for (const auto& [name, text] : variants) {
    SCOPED_TRACE(name);
    const Mesh m = ReadObj(WriteText(name, text));
    EXPECT_EQ(m.V, reference.V);
    EXPECT_EQ(m.U, reference.U);
    EXPECT_EQ(m.F, reference.F);
  }
  // Lines are still counted one per line ending (CRLF is one), so errors name the right one.
  const std::string cr_bad = WriteText("cr_bad.obj", "v 0 0 0\rv 1 0 0\r\rv 0 1 0\rf 1 2 9\r");
  ExpectThrowContaining([&] { ReadObj(cr_bad); }, cr_bad + ":5: vertex index 9 out of range");
  const std::string crlf_bad = WriteText("crlf_bad.obj", "v 0 0 0\r\nv 1 0 0\r\n\r\nv 0 1 0\r\nf 1 2 9\r\n");
  ExpectThrowContaining([&] { ReadObj(crlf_bad); }, crlf_bad + ":5: vertex index 9 out of range");
}

TEST(ObjTest, UnknownKeywordsAreErrorsNamingTheLineAndKnownOnesAreSkipped) {
  // OBJ is case-sensitive: an 'F' line was skipped silently (the mesh lost that face), a 'V' line
  // too (every later index then pointed one vertex off).
  const std::string upper_f = WriteText("upper_f.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nF 1 2 3\n");
  ExpectThrowContaining([&] { ReadObj(upper_f); },
                        upper_f + ":4: unknown keyword 'F' (OBJ keywords are lower case: 'f')");
  const std::string upper_v = WriteText("upper_v.obj", "v 0 0 0\nV 1 0 0\nv 0 1 0\nf 1 2 3\n");
  ExpectThrowContaining([&] { ReadObj(upper_v); }, upper_v + ":2: unknown keyword 'V'");
  const std::string typo = WriteText("typo.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nface 1 2 3\n");
  ExpectThrowContaining([&] { ReadObj(typo); }, typo + ":4: unknown keyword 'face'");
  // What exporters and ArcSim's save_obj write beside v, vt and f is skipped.
  const std::string rich = WriteText("rich.obj",
                                     "# exported\nmtllib cloth.mtl\no Cloth\ng flag\ns off\nusemtl red\n"
                                     "v 0 0 0\nnv 0 0 1\nnl 1\nv 1 0 0\nny 1 0 0\nv 0 1 0\nvl 2\nvt 0 0\nvt 1 0\n"
                                     "vt 0 1\nvn 0 0 1\nvp 0.5\ne 1 2\nea 0.1\ned 0\nel 3\nep 1\n"
                                     "f 1/1/1 2/2/1 3/3/1\ntl 2\nfs 1\nfd 0\ntm 0\ntp 1 0 0 0 1 0 0 0 1\nts 1 0 0 0 1 0 0 0 1\ntd 0\n"
                                     "l 1 2\np 3\n");
  const Mesh m = ReadObj(rich);
  EXPECT_EQ(m.V.rows(), 3);
  EXPECT_EQ(m.F.rows(), 1);
}

TEST(ObjTest, VerticesAtOnePointAreSaidAsACutNamingTheirLines) {
  // Two triangles sharing an edge by position only (vertices 5 and 6 copy 1 and 3): the simulated
  // cloth came apart there without a word. Said once per file, naming the vertices and lines; the
  // same mesh welded says nothing.
  const std::string cut = WriteText("cut.obj", "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 0\nv 1 1 0\n"
                                               "f 1 2 3\nf 5 6 4\n");
  ::testing::internal::CaptureStderr();
  EXPECT_NO_THROW(ReadObj(cut));
  EXPECT_NO_THROW(ReadObj(cut));
  const std::string said = ::testing::internal::GetCapturedStderr();
  EXPECT_NE(said.find("warning: " + cut + ": vertices 1 and 5 (lines 1 and 5) are at the same point, and 1 more such "
                      "pairs: the cloth is cut there"),
            std::string::npos)
      << said;
  EXPECT_EQ(said.find("warning", said.find("warning") + 1), std::string::npos) << "said twice: " << said;
  const std::string welded = WriteText("welded.obj", "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3\nf 1 3 4\n");
  ::testing::internal::CaptureStderr();
  EXPECT_NO_THROW(ReadObj(welded));
  const std::string quiet = ::testing::internal::GetCapturedStderr();
  EXPECT_EQ(quiet, "");
}

TEST(ValidateMeshTest, RejectsNaNRangeAndDegenerate) {
  Mesh m = Rectangle();
  m.V(1, 2) = std::numeric_limits<double>::quiet_NaN();
  ExpectThrowContaining([&] { ValidateMesh(m, "flag"); }, "flag: vertex 1 has a non-finite position");
  m = Rectangle();
  m.F(1, 2) = 9;
  ExpectThrowContaining([&] { ValidateMesh(m); }, "face 1 has vertex index 9 out of range");
  m = Rectangle();
  m.U.row(2) = m.U.row(0);
  ExpectThrowContaining([&] { ValidateMesh(m); }, "degenerate in material space");
  m = Rectangle();
  m.U.resize(3, 2);
  ExpectThrowContaining([&] { ValidateMesh(m); }, "U has 3 rows");
  EXPECT_NO_THROW(ValidateMesh(Rectangle()));
}

TEST(ValidateMeshTest, TopologyErrorsNameTheObjLineAndItsVertexNumbers) {
  // Two triangles of a square, consistently oriented: fine.
  const std::string square = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3\nf 1 3 4\n";
  EXPECT_NO_THROW(ReadObj(WriteText("square.obj", square)));
  // The second face turned round runs over the diagonal 1 -> 3 as the first does.
  const std::string flipped = WriteText("flipped.obj", "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3\nf 1 4 3\n");
  ExpectThrowContaining([&] { ReadObj(flipped); },
                        flipped + ":6: face runs from vertex 3 to vertex 1 as the face on line 5 does");
  // A third face on the diagonal: an edge of three faces.
  const std::string fin = WriteText("fin.obj", square + "v 0.8 0.2 1\nf 1 3 5\n");
  ExpectThrowContaining([&] { ReadObj(fin); }, fin + ":8: face runs from vertex 1 to vertex 3");
  // A vertex no face uses (it would have no mass), numbered as in the file.
  const std::string stray = WriteText("stray.obj", square + "v 9 9 0\n");
  ExpectThrowContaining([&] { ReadObj(stray); }, stray + ": vertex 5 belongs to no face");
  // A mesh only drawn (an OBJ frame to render) is not held to what the simulator needs.
  EXPECT_NO_THROW(ReadObj(flipped, /*topology=*/false));
  EXPECT_NO_THROW(ReadObj(stray, /*topology=*/false));
  // With texture coordinates: a stray vertex is still named as one (it was "has no texture
  // coordinate while others do"), and a drawn mesh keeps it; seams and corners without a vt
  // name the f line.
  const std::string textured = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvt 0 0\nvt 2 0\nvt 2 2\nvt 0 2\n"
                               "f 1/1 2/2 3/3\nf 1/1 3/3 4/4\n";
  const Mesh tex = ReadObj(WriteText("tex.obj", textured));
  EXPECT_EQ(tex.U(2, 0), 2.0);
  const std::string tex_stray = WriteText("tex_stray.obj", textured + "v 9 9 0\n");
  ExpectThrowContaining([&] { ReadObj(tex_stray); }, tex_stray + ": vertex 5 belongs to no face");
  EXPECT_EQ(ReadObj(tex_stray, /*topology=*/false).U(4, 0), 9.0);
  const std::string seam = WriteText("seam.obj", textured + "vt 5 5\nf 1/5 4/4 3/3\n");
  ExpectThrowContaining([&] { ReadObj(seam, false); }, seam + ":12: vertex 1 has texture coordinate 5 here and 1 on line 9");
  const std::string bare = WriteText("bare.obj", "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 1 1\n"
                                                 "f 1/1 2/2 3/3\nf 1 3 4\n");
  ExpectThrowContaining([&] { ReadObj(bare); }, bare + ":9: vertex 1 has no texture coordinate here");
  // Without lines (a mesh built in code), 0-based indices.
  Mesh m = Rectangle();
  m.F.row(1) = m.F.row(1).reverse().eval();
  ExpectThrowContaining([&] { ValidateMesh(m, "rect"); }, "rect: face 1 runs from");
}

TEST(RefineMeshTest, PreservesAreaAndBoundaryAndBoundsEdges) {
  Mesh m = Rectangle();
  m.V.col(2) << 0, 0.5, 0.5, 0;  // a bent (but planar-per-triangle) world shape
  const double area = SurfaceArea(m), rest = RestArea(m);
  const Mesh r = RefineMesh(m, 0.25);
  EXPECT_LE(MaxEdgeLength(r), 0.25);
  EXPECT_NEAR(SurfaceArea(r), area, 1e-12 * area);
  EXPECT_NEAR(RestArea(r), rest, 1e-12 * rest);
  // Original vertices keep their indices and positions.
  EXPECT_EQ(r.V.topRows(4), m.V);
  // Every boundary vertex of the refined mesh lies on the original boundary (the rectangle's sides).
  double perimeter = 0;
  for (const auto& [a, b] : BoundaryEdges(r)) {
    perimeter += (r.U.row(a) - r.U.row(b)).norm();
    for (int v : {a, b}) {
      const double u = r.U(v, 0), w = r.U(v, 1);
      EXPECT_TRUE(std::abs(u) < 1e-12 || std::abs(u - 3) < 1e-12 || std::abs(w) < 1e-12 ||
                  std::abs(w - 2) < 1e-12)
          << "vertex " << v << " at " << u << ", " << w;
    }
  }
  EXPECT_NEAR(perimeter, 10.0, 1e-12);
  // Uniform 1-to-4: the face count is 2 * 4^levels, and vertices are shared (no duplicates).
  EXPECT_EQ(r.F.rows() % 2, 0);
  const int levels = static_cast<int>(std::round(std::log(r.F.rows() / 2.0) / std::log(4.0)));
  EXPECT_EQ(r.F.rows(), 2 * (1 << (2 * levels)));
  const int side = 1 << levels;
  EXPECT_EQ(r.V.rows(), (side + 1) * (side + 1));
  EXPECT_NO_THROW(ValidateMesh(r));
  EXPECT_THROW(RefineMesh(m, 0.0), std::invalid_argument);
  // A size no cloth needs stops before the faces outgrow memory, saying why.
  try {
    RefineMesh(m, 1e-9);
    ADD_FAILURE() << "refined towards a billion faces";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("would make more than 2000000 faces"), std::string::npos) << e.what();
  }
}

TEST(SplitLongEdgesTest, SplitsOnlyLongEdgesAndStaysConforming) {
  // An irregular start: the rectangle refined once, then one vertex pulled sideways (in V and U)
  // so its edges differ in length.
  Mesh m = RefineMesh(Rectangle(), 0.5);  // edges 0.25, 0.375 and diagonals 0.45
  ASSERT_GT(m.V.rows(), 4);
  m.V(4, 0) += 0.1;
  m.U(4, 0) += 0.1;
  m.V.col(2) = 0.2 * m.V.col(0);  // tilted (planar) world shape
  ValidateMesh(m);
  const double area = SurfaceArea(m), rest = RestArea(m);
  const double max_edge = 0.4;
  const Mesh r = SplitLongEdges(m, max_edge);
  EXPECT_LE(MaxEdgeLength(r), max_edge);
  for (int f = 0; f < r.F.rows(); ++f)
    for (int c = 0; c < 3; ++c)
      EXPECT_LE((r.U.row(r.F(f, c)) - r.U.row(r.F(f, (c + 1) % 3))).norm(), max_edge + 1e-12);
  EXPECT_NEAR(SurfaceArea(r), area, 1e-12 * area);
  EXPECT_NEAR(RestArea(r), rest, 1e-12 * rest);
  EXPECT_EQ(r.V.topRows(m.V.rows()), m.V);
  EXPECT_EQ(r.U.topRows(m.U.rows()), m.U);
  EXPECT_NO_THROW(ValidateMesh(r));
  // Conforming and consistently oriented: every directed edge once, and every interior edge in
  // both directions (no hanging midpoints); the boundary is the rectangle's perimeter.
  std::set<std::pair<int, int>> directed;
  for (int f = 0; f < r.F.rows(); ++f)
    for (int c = 0; c < 3; ++c)
      EXPECT_TRUE(directed.insert({r.F(f, c), r.F(f, (c + 1) % 3)}).second) << "face " << f;
  double perimeter = 0;
  for (const auto& [a, b] : directed)
    if (!directed.count({b, a})) perimeter += (r.U.row(a) - r.U.row(b)).norm();
  EXPECT_NEAR(perimeter, 10.0, 1e-12);
  // Fewer vertices than uniform refinement to the same bound, and short edges kept: some edge
  // of the input survives unsplit.
  EXPECT_LT(r.V.rows(), RefineMesh(m, max_edge).V.rows());
  int kept = 0;
  for (const auto& [a, b] : directed) kept += (a < m.V.rows() && b < m.V.rows());
  EXPECT_GT(kept, 0);
  // Nothing to split: the same mesh.
  const Mesh same = SplitLongEdges(r, max_edge);
  EXPECT_EQ(same.V, r.V);
  EXPECT_EQ(same.F, r.F);
  EXPECT_THROW(SplitLongEdges(m, 0.0), std::invalid_argument);
}

}  // namespace
}  // namespace clothwind::sim
