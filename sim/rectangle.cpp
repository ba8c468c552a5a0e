#include "sim/rectangle.hpp"

#include <stdexcept>

namespace yarnhom::sim {

Mesh make_rectangle(double width, double height, int nx, int ny) {
  if (!(width > 0) || !(height > 0)) throw std::invalid_argument("rectangle: width and height must be positive");
  if (nx < 1 || ny < 1) throw std::invalid_argument("rectangle: needs at least one quad per side");
  Mesh m;
  const int n = (nx + 1) * (ny + 1);
  m.rest.resize(n, 2);
  m.x.resize(n, 3);
  for (int j = 0; j <= ny; ++j)
    for (int i = 0; i <= nx; ++i) {
      const int v = rectangle_vertex(nx, i, j);
      m.rest(v, 0) = width * i / nx;
      m.rest(v, 1) = height * j / ny;
      m.x.row(v) << m.rest(v, 0), m.rest(v, 1), 0.0;
    }
  m.tris.resize(2 * nx * ny, 3);
  int t = 0;
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) {
      const int a = rectangle_vertex(nx, i, j), b = rectangle_vertex(nx, i + 1, j);
      const int c = rectangle_vertex(nx, i + 1, j + 1), d = rectangle_vertex(nx, i, j + 1);
      if ((i + j) % 2 == 0) {  // diagonal a-c
        m.tris.row(t++) << a, b, c;
        m.tris.row(t++) << a, c, d;
      } else {  // diagonal b-d
        m.tris.row(t++) << a, b, d;
        m.tris.row(t++) << b, c, d;
      }
    }
  finish_mesh(m, "rectangle");
  return m;
}

}  // namespace yarnhom::sim
