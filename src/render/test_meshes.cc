#include "render/test_meshes.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace clothwind::render {

namespace {
ClothMesh Grid(int nx, int ny) {
  if (nx < 2 || ny < 2) throw std::invalid_argument("test mesh: need at least 2x2 vertices");
  ClothMesh m;
  m.V.resize(nx * ny, 3);
  m.UV.resize(nx * ny, 2);
  m.F.resize(2 * (nx - 1) * (ny - 1), 3);
  int f = 0;
  for (int j = 0; j + 1 < ny; ++j)
    for (int i = 0; i + 1 < nx; ++i) {
      const int a = j * nx + i, b = a + 1, c = a + nx, d = c + 1;
      m.F.row(f++) << a, b, d;
      m.F.row(f++) << a, d, c;
    }
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i)
      m.UV.row(j * nx + i) << static_cast<double>(i) / (nx - 1), static_cast<double>(j) / (ny - 1);
  return m;
}
}  // namespace

ClothMesh WavingFlag(int nx, int ny, double width, double height, double time,
                     double amplitude, double frequency) {
  ClothMesh m = Grid(nx, ny);
  const double k = 2.0 * M_PI / (0.9 * width);  // about one wavelength along the flag
  const double omega = 2.0 * M_PI * frequency;
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) {
      const double s = m.UV(j * nx + i, 0), t = m.UV(j * nx + i, 1);
      const double x = s * width, z = t * height;
      const double a = amplitude * std::pow(s, 1.3);
      const double phase = k * x - omega * time + 0.6 * (1.0 - t);
      const double y = a * std::sin(phase);
      // Waves shorten the flag's reach; the fly end droops a little.
      const double xr = x - 0.08 * a * (1.0 - std::cos(2 * phase));
      const double zr = z - 0.12 * height * s * s + 0.05 * a * std::cos(phase);
      m.V.row(j * nx + i) << xr, y, zr;
    }
  return m;
}

ClothMesh HangingCloth(int nx, int ny, double width, double height, double time,
                       double amplitude, double frequency) {
  ClothMesh m = Grid(nx, ny);
  const double omega = 2.0 * M_PI * frequency;
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) {
      const double s = m.UV(j * nx + i, 0), t = m.UV(j * nx + i, 1);
      const double hang = 1.0 - t;  // 0 at the rod, 1 at the bottom edge
      const double folds = std::sin(2.0 * M_PI * 2.5 * s + omega * time);
      const double x = amplitude * hang * (0.6 + 0.4 * std::sin(omega * time + 1.3 * hang)) +
                       0.04 * hang * folds;
      m.V.row(j * nx + i) << x, s * width, t * height - 0.03 * hang * x / std::max(amplitude, 1e-9);
    }
  return m;
}

ClothMesh FlatCloth(int nx, int ny, double width, double height) {
  ClothMesh m = Grid(nx, ny);
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) {
      const double s = m.UV(j * nx + i, 0), t = m.UV(j * nx + i, 1);
      m.V.row(j * nx + i) << 0.0, s * width, t * height;
    }
  return m;
}

}  // namespace clothwind::render
