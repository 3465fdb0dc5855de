#include "sim/mesh.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <map>
#include <sstream>
#include <stdexcept>
#include <tuple>
#include <utility>
#include <vector>

#include <Eigen/Geometry>

#include "common/atomic_file.h"
#include "common/formatted.h"
#include "common/regular_file.h"
#include "sim/warn_once.h"

namespace clothwind::sim {
namespace {

[[noreturn]] void ObjError(const std::string& path, int line, const std::string& what) {
  throw std::runtime_error(path + ":" + std::to_string(line) + ": " + what);
}

// Parses an OBJ index (1-based, or negative = relative to the end) into a 0-based one.
int ObjIndex(const std::string& token, int count, const std::string& path, int line,
             const char* kind) {
  if (token.empty()) ObjError(path, line, std::string("empty ") + kind + " index");
  size_t used = 0;
  long value = 0;
  try {
    value = std::stol(token, &used);
  } catch (const std::exception&) {
    ObjError(path, line, std::string("expected an integer ") + kind + " index, got '" + token + "'");
  }
  if (used != token.size())
    ObjError(path, line, std::string("expected an integer ") + kind + " index, got '" + token + "'");
  long index = value > 0 ? value - 1 : count + value;
  if (value == 0 || index < 0 || index >= count)
    ObjError(path, line, std::string(kind) + " index " + token + " out of range (have " +
                             std::to_string(count) + ")");
  return static_cast<int>(index);
}

// OBJ keywords that carry nothing this reader uses, skipped: the standard ones (normals, groups,
// objects, smoothing, materials, lines and points, free-form geometry) and the per-node, edge and
// face annotations ArcSim's save_obj writes (labels, plastic rest positions, velocities, ideal
// angles, damage, plastic strains). Anything else is refused naming its line: 'F' or 'V' (wrong
// case) used to be skipped silently, losing that face or vertex.
bool IsIgnoredObjKeyword(const std::string& key) {
  static const char* const kIgnored[] = {
      // Wavefront OBJ
      "vn", "vp", "o", "g", "s", "mg", "usemtl", "mtllib", "l", "p", "cstype", "deg", "bmat", "step", "curv",
      "curv2", "surf", "parm", "trim", "hole", "scrv", "sp", "end", "con", "bevel", "c_interp", "d_interp", "lod",
      "shadow_obj", "trace_obj", "ctech", "stech", "call", "csh",
      // ArcSim 0.2 (io.cpp)
      "vl", "ny", "nv", "nl", "e", "ea", "ed", "el", "ep", "tm", "tp", "ts", "td", "fl",
      // ArcSim's face labels: save_obj writes "tl", load_obj also reads "fs" and "fd"
      "tl", "fs", "fd"};
  for (const char* k : kIgnored)
    if (key == k) return true;
  return false;
}

// Splits `text` into lines ending in "\n", "\r\n" or a lone "\r" (files saved by old Mac tools:
// read with getline('\n') such a file was one line, and an OBJ whose first line is a comment
// read as "no vertices"). The line terminators are dropped.
std::vector<std::string> SplitLines(const std::string& text) {
  std::vector<std::string> lines;
  size_t start = 0;
  for (size_t i = 0; i < text.size(); ++i) {
    if (text[i] != '\n' && text[i] != '\r') continue;
    lines.push_back(text.substr(start, i - start));
    if (text[i] == '\r' && i + 1 < text.size() && text[i + 1] == '\n') ++i;
    start = i + 1;
  }
  if (start < text.size()) lines.push_back(text.substr(start));
  return lines;
}

double TriangleArea3(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c) {
  return 0.5 * (b - a).cross(c - a).norm();
}

double TriangleArea2(const Eigen::Vector2d& a, const Eigen::Vector2d& b, const Eigen::Vector2d& c) {
  const Eigen::Vector2d e1 = b - a, e2 = c - a;
  return 0.5 * std::abs(e1.x() * e2.y() - e1.y() * e2.x());
}

// Midpoints of a mesh's edges for subdivision: each edge's midpoint (world and rest coordinates)
// is made once and numbered after the mesh's own vertices, which keep their indices (handles
// refer to them).
class EdgeMidpoints {
 public:
  explicit EdgeMidpoints(const Mesh& mesh) : mesh_(mesh), nv_(static_cast<int>(mesh.V.rows())) {}

  // Index of the midpoint of edge (a, b), made on first request.
  int Get(int a, int b) {
    const auto key = std::minmax(a, b);
    auto it = index_.find(key);
    if (it != index_.end()) return it->second;
    const int id = nv_ + static_cast<int>(V_.size());
    V_.push_back(0.5 * (mesh_.V.row(a) + mesh_.V.row(b)).transpose());
    U_.push_back(0.5 * (mesh_.U.row(a) + mesh_.U.row(b)).transpose());
    index_.emplace(key, id);
    return id;
  }
  // Rest coordinates of vertex i, old or new.
  Eigen::Vector2d U(int i) const {
    return i < nv_ ? Eigen::Vector2d(mesh_.U.row(i).transpose()) : U_[i - nv_];
  }
  bool empty() const { return V_.empty(); }
  // The mesh's vertices followed by the midpoints, with faces F.
  Mesh Build(Eigen::MatrixX3i F) const {
    Mesh next;
    next.V.resize(nv_ + V_.size(), 3);
    next.U.resize(nv_ + U_.size(), 2);
    next.V.topRows(nv_) = mesh_.V;
    next.U.topRows(nv_) = mesh_.U;
    for (size_t i = 0; i < V_.size(); ++i) {
      next.V.row(nv_ + i) = V_[i].transpose();
      next.U.row(nv_ + i) = U_[i].transpose();
    }
    next.F = std::move(F);
    return next;
  }

 private:
  const Mesh& mesh_;
  int nv_;
  std::map<std::pair<int, int>, int> index_;
  std::vector<Eigen::Vector3d> V_;
  std::vector<Eigen::Vector2d> U_;
};

}  // namespace

namespace {

// Says on stderr (WarnOnce) when two vertices the faces use lie at the same point:
// an unwelded seam (an exporter's duplicate), where the simulated cloth comes apart without a
// word (a square's middle row copied: half the cloth fell away from the other). A slit may be
// meant (a swallowtail flag's), so it is said, not refused.
void WarnOfCoincidentVertices(const Mesh& mesh, const std::string& path, const std::vector<int>& lines) {
  std::vector<int> used;
  std::vector<char> in_face(mesh.V.rows(), 0);
  for (int f = 0; f < mesh.F.rows(); ++f)
    for (int c = 0; c < 3; ++c) in_face[mesh.F(f, c)] = 1;
  for (int v = 0; v < mesh.V.rows(); ++v)
    if (in_face[v]) used.push_back(v);
  auto point = [&](int v) { return std::make_tuple(mesh.V(v, 0), mesh.V(v, 1), mesh.V(v, 2)); };
  // By position, then number: equal points side by side, the lower-numbered first.
  std::sort(used.begin(), used.end(), [&](int a, int b) {
    return std::tuple_cat(point(a), std::make_tuple(a)) < std::tuple_cat(point(b), std::make_tuple(b));
  });
  int pairs = 0, first_a = -1, first_b = -1;
  for (size_t k = 1; k < used.size(); ++k) {
    if (point(used[k]) != point(used[k - 1])) continue;
    if (pairs++ == 0) {
      first_a = used[k - 1];
      first_b = used[k];
    }
  }
  if (pairs == 0) return;
  std::ostringstream what;
  what << path << ": vertices " << first_a + 1 << " and " << first_b + 1 << " (lines " << lines[first_a] << " and "
       << lines[first_b] << ") are at the same point"
       << (pairs > 1 ? ", and " + std::to_string(pairs - 1) + " more such pairs" : std::string())
       << ": the cloth is cut there (not welded); merge them if it should hold together";
  WarnOnce({what.str()});
}

}  // namespace

Mesh ReadObj(const std::string& path, bool topology) {
  // A folder opened as a stream read as empty ("no vertices ('v' lines)"), and a pipe waited for a
  // writer for ever.
  RefuseNonRegularFile(path, "an OBJ file");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error(path + ": cannot open OBJ file");
  std::ostringstream contents;
  contents << in.rdbuf();
  std::string text = contents.str();
  // A UTF-8 byte order mark (Windows editors write one) would glue itself to the first keyword.
  if (text.compare(0, 3, "\xEF\xBB\xBF") == 0) text.erase(0, 3);
  std::vector<Eigen::Vector3d> positions;
  std::vector<Eigen::Vector2d> texcoords;
  std::vector<Eigen::Vector3i> faces;
  std::vector<Eigen::Vector3i> face_tex;  // -1 when a corner has no vt
  std::vector<int> face_lines;            // the line of each triangle's f
  std::vector<int> position_lines;        // the line of each v
  int line_no = 0;
  auto read_numbers = [&](std::istringstream& s, int n, double* out, const char* what) {
    for (int i = 0; i < n; ++i) {
      std::string tok;
      if (!(s >> tok))
        ObjError(path, line_no, std::string("expected ") + std::to_string(n) + " numbers after '" +
                                    what + "'");
      char* end = nullptr;
      out[i] = std::strtod(tok.c_str(), &end);
      if (end == tok.c_str() || *end != '\0')
        ObjError(path, line_no, std::string("expected a number in '") + what + "' line, got '" +
                                    tok + "'");
      if (!std::isfinite(out[i]))
        ObjError(path, line_no, std::string("non-finite value '") + tok + "' in '" + what + "'");
    }
  };
  for (const std::string& line : SplitLines(text)) {
    ++line_no;
    std::istringstream s(line);
    std::string key;
    if (!(s >> key) || key[0] == '#') continue;
    if (key == "v") {
      double x[3];
      read_numbers(s, 3, x, "v");
      positions.emplace_back(x[0], x[1], x[2]);
      position_lines.push_back(line_no);
    } else if (key == "vt") {
      double u[2];
      read_numbers(s, 2, u, "vt");
      texcoords.emplace_back(u[0], u[1]);
    } else if (key == "f") {
      std::vector<int> vi, ti;
      std::string tok;
      while (s >> tok) {
        const size_t slash = tok.find('/');
        const std::string vtok = tok.substr(0, slash);
        vi.push_back(ObjIndex(vtok, static_cast<int>(positions.size()), path, line_no, "vertex"));
        int t = -1;
        if (slash != std::string::npos) {
          const size_t slash2 = tok.find('/', slash + 1);
          const std::string ttok = tok.substr(slash + 1, slash2 == std::string::npos
                                                              ? std::string::npos
                                                              : slash2 - slash - 1);
          if (!ttok.empty())
            t = ObjIndex(ttok, static_cast<int>(texcoords.size()), path, line_no, "texture");
        }
        ti.push_back(t);
      }
      if (vi.size() < 3)
        ObjError(path, line_no, "a face needs at least 3 vertices, got " + std::to_string(vi.size()));
      for (size_t k = 2; k < vi.size(); ++k) {  // fan triangulation of polygons
        faces.emplace_back(vi[0], vi[k - 1], vi[k]);
        face_tex.emplace_back(ti[0], ti[k - 1], ti[k]);
        face_lines.push_back(line_no);
      }
    } else if (!IsIgnoredObjKeyword(key)) {
      std::string lower = key;
      std::transform(lower.begin(), lower.end(), lower.begin(), [](unsigned char c) { return std::tolower(c); });
      const bool known = lower == "v" || lower == "vt" || lower == "f" || IsIgnoredObjKeyword(lower);
      ObjError(path, line_no, "unknown keyword '" + key + "'" +
                                  (known ? " (OBJ keywords are lower case: '" + lower + "')" : ""));
    }
  }
  if (positions.empty()) throw std::runtime_error(path + ": no vertices ('v' lines)");
  if (faces.empty()) throw std::runtime_error(path + ": no faces ('f' lines)");

  Mesh mesh;
  const int nv = static_cast<int>(positions.size());
  mesh.V.resize(nv, 3);
  for (int i = 0; i < nv; ++i) mesh.V.row(i) = positions[i].transpose();
  mesh.F.resize(static_cast<int>(faces.size()), 3);
  for (size_t f = 0; f < faces.size(); ++f) mesh.F.row(f) = faces[f].transpose();
  // Material coordinates: the vt of each vertex when all its corners agree, else ArcSim's x,y.
  mesh.U = mesh.V.leftCols(2);
  // A vertex no face uses (exporters leave them; ValidateMesh names them where they matter) keeps
  // its x,y; the errors name the `f` line where a vertex's corners disagree or lack a vt.
  bool any_tex = false;
  std::vector<int> vt_of(nv, -1), vt_line(nv, 0), bare_line(nv, 0);
  for (size_t f = 0; f < faces.size(); ++f) {
    for (int c = 0; c < 3; ++c) {
      const int t = face_tex[f][c], v = faces[f][c];
      if (t < 0) {
        if (bare_line[v] == 0) bare_line[v] = face_lines[f];
        continue;
      }
      any_tex = true;
      if (vt_of[v] >= 0 && (texcoords[vt_of[v]] - texcoords[t]).norm() > 1e-12)
        ObjError(path, face_lines[f], "vertex " + std::to_string(v + 1) + " has texture coordinate " +
                                          std::to_string(t + 1) + " here and " + std::to_string(vt_of[v] + 1) +
                                          " on line " + std::to_string(vt_line[v]) +
                                          " (texture seams are not supported)");
      if (vt_of[v] < 0) vt_line[v] = face_lines[f];
      vt_of[v] = t;
    }
  }
  if (any_tex) {
    for (int v = 0; v < nv; ++v) {
      if (bare_line[v] > 0)
        ObjError(path, bare_line[v], "vertex " + std::to_string(v + 1) +
                                         " has no texture coordinate here while other corners have one");
      if (vt_of[v] >= 0) mesh.U.row(v) = texcoords[vt_of[v]].transpose();
    }
  }
  ValidateMesh(mesh, path, face_lines, topology);
  if (topology) WarnOfCoincidentVertices(mesh, path, position_lines);
  return mesh;
}

void WriteObj(const std::string& path, const Mesh& mesh) {
  std::ostringstream out;
  out.precision(17);
  out << "# clothwind mesh: " << mesh.V.rows() << " vertices, " << mesh.F.rows() << " faces\n";
  for (int i = 0; i < mesh.V.rows(); ++i)
    out << "v " << mesh.V(i, 0) << ' ' << mesh.V(i, 1) << ' ' << mesh.V(i, 2) << '\n';
  const bool tex = mesh.U.rows() == mesh.V.rows() && mesh.U.rows() > 0;
  if (tex)
    for (int i = 0; i < mesh.U.rows(); ++i) out << "vt " << mesh.U(i, 0) << ' ' << mesh.U(i, 1) << '\n';
  for (int f = 0; f < mesh.F.rows(); ++f) {
    out << 'f';
    for (int c = 0; c < 3; ++c) {
      out << ' ' << mesh.F(f, c) + 1;
      if (tex) out << '/' << mesh.F(f, c) + 1;
    }
    out << '\n';
  }
  // Through the one atomic writer (a temporary name of this process, fsync, rename, removed on
  // failure): a fixed "<path>.tmp" was left behind by a failed write, and two writers shared it.
  clothwind::WriteFileAtomically(path, out.str());
}

void ValidateMesh(const Mesh& mesh, const std::string& what, const std::vector<int>& obj_lines, bool topology) {
  // An OBJ's reader knows each triangle's line and numbers vertices from 1, as the file does.
  const bool obj = !obj_lines.empty() && static_cast<int>(obj_lines.size()) == mesh.F.rows();
  auto vertex = [&](int i) { return "vertex " + std::to_string(obj ? i + 1 : i); };
  auto face = [&](int f) {
    return obj ? ":" + std::to_string(obj_lines[f]) + ": face" : ": face " + std::to_string(f);
  };
  const int nv = static_cast<int>(mesh.V.rows());
  if (nv == 0) throw std::invalid_argument(what + ": mesh has no vertices");
  if (mesh.F.rows() == 0) throw std::invalid_argument(what + ": mesh has no faces");
  if (mesh.U.rows() != nv)
    throw std::invalid_argument(what + ": U has " + std::to_string(mesh.U.rows()) +
                                " rows, expected one per vertex (" + std::to_string(nv) + ")");
  for (int i = 0; i < nv; ++i) {
    if (!mesh.V.row(i).allFinite())
      throw std::invalid_argument(what + ": " + vertex(i) + " has a non-finite position (NaN or inf)");
    if (!mesh.U.row(i).allFinite())
      throw std::invalid_argument(what + ": " + vertex(i) + " has a non-finite material coordinate (NaN or inf)");
  }
  const double scale = std::max(1e-300, (mesh.V.colwise().maxCoeff() - mesh.V.colwise().minCoeff()).norm());
  const double uscale = std::max(1e-300, (mesh.U.colwise().maxCoeff() - mesh.U.colwise().minCoeff()).norm());
  for (int f = 0; f < mesh.F.rows(); ++f) {
    const Eigen::Vector3i t = mesh.F.row(f).transpose();
    for (int c = 0; c < 3; ++c)
      if (t[c] < 0 || t[c] >= nv)
        throw std::invalid_argument(what + face(f) + " has vertex index " + std::to_string(t[c]) +
                                    " out of range [0, " + std::to_string(nv) + ")");
    if (t[0] == t[1] || t[1] == t[2] || t[0] == t[2])
      throw std::invalid_argument(what + face(f) + " repeats a vertex");
    const double a = TriangleArea3(mesh.V.row(t[0]), mesh.V.row(t[1]), mesh.V.row(t[2]));
    if (!(a > 1e-12 * scale * scale))
      throw std::invalid_argument(what + face(f) + " is degenerate (zero area in world space)");
    const double ua = TriangleArea2(mesh.U.row(t[0]), mesh.U.row(t[1]), mesh.U.row(t[2]));
    if (!(ua > 1e-12 * uscale * uscale))
      throw std::invalid_argument(what + face(f) + " is degenerate in material space (zero rest area)");
  }
  if (!topology) return;
  // Topology, which the simulator needs and reported late (after refinement, in refined indices,
  // naming no file): every vertex in a face (a vertex in none has no mass), and every edge used
  // at most once in each direction (a face turned the other way round, or an edge of three faces,
  // leaves no consistent hinge).
  std::vector<bool> used(nv, false);
  std::map<std::pair<int, int>, int> directed;  // (from, to) -> the face that uses it
  for (int f = 0; f < mesh.F.rows(); ++f) {
    for (int c = 0; c < 3; ++c) {
      const int a = mesh.F(f, c), b = mesh.F(f, (c + 1) % 3);
      used[a] = true;
      const auto [it, fresh] = directed.emplace(std::make_pair(a, b), f);
      if (!fresh)
        throw std::invalid_argument(what + face(f) + " runs from " + vertex(a) + " to " + vertex(b) + " as " +
                                    (obj ? "the face on line " + std::to_string(obj_lines[it->second])
                                         : "face " + std::to_string(it->second)) +
                                    " does: the faces are oriented inconsistently, or the edge has more than "
                                    "two faces");
    }
  }
  for (int i = 0; i < nv; ++i)
    if (!used[i]) throw std::invalid_argument(what + ": " + vertex(i) + " belongs to no face (it would have no mass)");
}

Mesh RefineMesh(const Mesh& input, double max_edge) {
  if (!(max_edge > 0)) throw std::invalid_argument("RefineMesh: max_edge must be > 0");
  ValidateMesh(input, "RefineMesh input");
  Mesh mesh = input;
  auto longest = [](const Mesh& m) {
    double l = 0;
    for (int f = 0; f < m.F.rows(); ++f)
      for (int c = 0; c < 3; ++c) {
        const int a = m.F(f, c), b = m.F(f, (c + 1) % 3);
        l = std::max(l, (m.V.row(a) - m.V.row(b)).norm());
        l = std::max(l, (m.U.row(a) - m.U.row(b)).norm());
      }
    return l;
  };
  for (int level = 0; longest(mesh) > max_edge; ++level) {
    if (level >= 12) throw std::invalid_argument("RefineMesh: max_edge too small (over 12 levels)");
    const int nf = static_cast<int>(mesh.F.rows());
    // Each level quadruples the faces: bounded before allocating (a remeshing size of 1e-9 went
    // on towards 134M faces and gigabytes before the level limit). Cloths here have ~1e3-1e4.
    constexpr int kMaxFaces = 2000000;
    if (nf > kMaxFaces / 4)
      throw std::invalid_argument("RefineMesh: max_edge " + FormattedNumber(max_edge) + " m would make more than " +
                                  std::to_string(kMaxFaces) + " faces");
    EdgeMidpoints mid(mesh);
    Eigen::MatrixX3i F(4 * nf, 3);
    for (int f = 0; f < nf; ++f) {
      const int a = mesh.F(f, 0), b = mesh.F(f, 1), c = mesh.F(f, 2);
      const int ab = mid.Get(a, b), bc = mid.Get(b, c), ca = mid.Get(c, a);
      F.row(4 * f + 0) << a, ab, ca;
      F.row(4 * f + 1) << ab, b, bc;
      F.row(4 * f + 2) << ca, bc, c;
      F.row(4 * f + 3) << ab, bc, ca;
    }
    mesh = mid.Build(std::move(F));
  }
  return mesh;
}

Mesh SplitLongEdges(const Mesh& input, double max_edge) {
  if (!(max_edge > 0)) throw std::invalid_argument("SplitLongEdges: max_edge must be > 0");
  ValidateMesh(input, "SplitLongEdges input");
  Mesh mesh = input;
  auto length = [](const Mesh& m, int a, int b) {
    return std::max((m.V.row(a) - m.V.row(b)).norm(), (m.U.row(a) - m.U.row(b)).norm());
  };
  for (int pass = 0;; ++pass) {
    const int nf = static_cast<int>(mesh.F.rows());
    EdgeMidpoints midpoints(mesh);
    // Midpoint of edge (a, b) if it is long, else -1.
    auto mid = [&](int a, int b) { return length(mesh, a, b) <= max_edge ? -1 : midpoints.Get(a, b); };
    auto u_of = [&](int i) { return midpoints.U(i); };
    std::vector<Eigen::Vector3i> faces;
    faces.reserve(4 * nf);
    for (int f = 0; f < nf; ++f) {
      const int v[3] = {mesh.F(f, 0), mesh.F(f, 1), mesh.F(f, 2)};
      int m[3];
      for (int c = 0; c < 3; ++c) m[c] = mid(v[c], v[(c + 1) % 3]);
      const int split = (m[0] >= 0) + (m[1] >= 0) + (m[2] >= 0);
      if (split == 0) {
        faces.emplace_back(v[0], v[1], v[2]);
      } else if (split == 3) {
        faces.emplace_back(v[0], m[0], m[2]);
        faces.emplace_back(m[0], v[1], m[1]);
        faces.emplace_back(m[2], m[1], v[2]);
        faces.emplace_back(m[0], m[1], m[2]);
      } else {
        // Rotate (keeping the orientation) so that edge (a, b) is split, and for two splits
        // also (b, c) while (c, a) is not.
        int r = 0;
        if (split == 1) {
          while (m[r] < 0) ++r;
        } else {
          while (m[(r + 2) % 3] >= 0) ++r;
        }
        const int a = v[r], b = v[(r + 1) % 3], c = v[(r + 2) % 3], mab = m[r], mbc = m[(r + 1) % 3];
        if (split == 1) {
          faces.emplace_back(a, mab, c);
          faces.emplace_back(mab, b, c);
        } else {
          faces.emplace_back(mab, b, mbc);
          // The quad (a, mab, mbc, c), cut along its shorter diagonal.
          if ((u_of(a) - u_of(mbc)).norm() <= (u_of(mab) - u_of(c)).norm()) {
            faces.emplace_back(a, mab, mbc);
            faces.emplace_back(a, mbc, c);
          } else {
            faces.emplace_back(a, mab, c);
            faces.emplace_back(mab, mbc, c);
          }
        }
      }
    }
    if (midpoints.empty()) return mesh;
    if (pass >= 12) throw std::invalid_argument("SplitLongEdges: max_edge not reached in 12 passes");
    Eigen::MatrixX3i F(faces.size(), 3);
    for (size_t i = 0; i < faces.size(); ++i) F.row(i) = faces[i].transpose();
    mesh = midpoints.Build(std::move(F));
  }
}

double MaxEdgeLength(const Mesh& mesh) {
  double l = 0;
  for (int f = 0; f < mesh.F.rows(); ++f)
    for (int c = 0; c < 3; ++c)
      l = std::max(l, (mesh.V.row(mesh.F(f, c)) - mesh.V.row(mesh.F(f, (c + 1) % 3))).norm());
  return l;
}

double SurfaceArea(const Mesh& mesh) {
  double a = 0;
  for (int f = 0; f < mesh.F.rows(); ++f)
    a += TriangleArea3(mesh.V.row(mesh.F(f, 0)), mesh.V.row(mesh.F(f, 1)), mesh.V.row(mesh.F(f, 2)));
  return a;
}

double RestArea(const Mesh& mesh) {
  double a = 0;
  for (int f = 0; f < mesh.F.rows(); ++f)
    a += TriangleArea2(mesh.U.row(mesh.F(f, 0)), mesh.U.row(mesh.F(f, 1)), mesh.U.row(mesh.F(f, 2)));
  return a;
}

}  // namespace clothwind::sim
