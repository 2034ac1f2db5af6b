// An app's frame loop around one body: a soft slab falls on a floor, one end is grabbed and
// lifted, then let go; every frame "draws" the surface (here: sums its area) and reads the
// floor's push. Prints one line per phase and exits 1 if the body went through the floor, was
// not lifted, or did not land again.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <femcourse/simulator.hpp>
#include <utility>
#include <vector>

namespace {

using Vec = std::array<double, 3>;

// Appends tetrahedron t, two of its nodes swapped if it is inverted (the library refuses those).
void add_positive(femcourse::BodyDescription& d, std::array<int, 4> t) {
  const auto x = [&](int n, int r) {
    return d.rest_positions[3 * static_cast<std::size_t>(n) + r];
  };
  double e[3][3];
  for (int a = 0; a < 3; ++a)
    for (int r = 0; r < 3; ++r) e[a][r] = x(t[a + 1], r) - x(t[0], r);
  const double det = e[0][0] * (e[1][1] * e[2][2] - e[1][2] * e[2][1]) -
                     e[0][1] * (e[1][0] * e[2][2] - e[1][2] * e[2][0]) +
                     e[0][2] * (e[1][0] * e[2][1] - e[1][1] * e[2][0]);
  if (det < 0.0) std::swap(t[2], t[3]);
  d.tetrahedra.insert(d.tetrahedra.end(), t.begin(), t.end());
}

// An nx x ny x nz grid of cubes of side h, each as five tetrahedra (a middle one and four
// corners), alternating so that neighbours share their faces' diagonals.
femcourse::BodyDescription slab(int nx, int ny, int nz, double h) {
  femcourse::BodyDescription d;
  const auto id = [&](int i, int j, int k) { return (k * (ny + 1) + j) * (nx + 1) + i; };
  for (int k = 0; k <= nz; ++k)
    for (int j = 0; j <= ny; ++j)
      for (int i = 0; i <= nx; ++i)
        d.rest_positions.insert(d.rest_positions.end(), {i * h, j * h, k * h});
  for (int k = 0; k < nz; ++k)
    for (int j = 0; j < ny; ++j)
      for (int i = 0; i < nx; ++i) {
        int c[8];  // corner (a, b, e) at bit a + 2b + 4e
        for (int q = 0; q < 8; ++q) c[q] = id(i + (q & 1), j + (q >> 1 & 1), k + (q >> 2));
        const bool even = (i + j + k) % 2 == 0;
        const std::array<std::array<int, 4>, 5> tets =
            even ? std::array<std::array<int, 4>, 5>{{{0, 1, 2, 4},
                                                      {3, 2, 1, 7},
                                                      {5, 4, 7, 1},
                                                      {6, 7, 4, 2},
                                                      {1, 2, 4, 7}}}
                 : std::array<std::array<int, 4>, 5>{
                       {{1, 0, 5, 3}, {2, 3, 0, 6}, {4, 5, 6, 0}, {7, 6, 5, 3}, {0, 3, 6, 5}}};
        for (const auto& t : tets) add_positive(d, {c[t[0]], c[t[1]], c[t[2]], c[t[3]]});
      }
  return d;
}

double lowest(const femcourse::Body& body) {
  double z = INFINITY;
  for (int i = 0; i < body.num_nodes(); ++i) z = std::min(z, body.position(i)[2]);
  return z;
}

// What a renderer would upload: the surface's triangles at the current positions.
double surface_area(const femcourse::Body& body) {
  double area = 0.0;
  for (const auto& t : body.surface()) {
    const Vec a = body.position(t[0]), b = body.position(t[1]), c = body.position(t[2]);
    const Vec u{b[0] - a[0], b[1] - a[1], b[2] - a[2]}, v{c[0] - a[0], c[1] - a[1], c[2] - a[2]};
    const Vec n{u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]};
    area += 0.5 * std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
  }
  return area;
}

// What holds the body up [N]: the reactions of its constraints (the floor, the hand).
double floor_push(const femcourse::Body& body) {
  double up = 0.0;
  for (const auto& r : body.reactions()) up += r.force[2];
  return up;
}

void frames(femcourse::Body& body, int n, const char* phase) {
  double area = 0.0;
  for (int f = 0; f < n; ++f) {
    body.step();
    area = surface_area(body);  // draw
  }
  std::printf(
      "%-28s t %.2f s  lowest z %+.4f m  floor contacts %3zu  held up by %7.2f N  "
      "surface %zu triangles, %.4f m^2\n",
      phase, body.time(), lowest(body), body.floor_contacts().size(), floor_push(body),
      body.surface().size(), area);
}

}  // namespace

int main() {
  femcourse::BodyDescription d = slab(12, 4, 2, 0.05);
  d.youngs_modulus = 2e5;
  d.damping_alpha = 1.0;
  d.threads = 1;  // a small body: one thread keeps the frame times steady (docs/library.md)
  femcourse::Body body(d);
  body.set_warning_handler([](const std::string& w) { std::printf("warning: %s\n", w.c_str()); });
  const double floor = -0.05;
  body.set_floor({0.0, 0.0, floor}, {0.0, 0.0, 1.0});
  frames(body, 60, "dropped on the floor");
  const bool landed = !body.floor_contacts().empty() && lowest(body) >= floor - 1e-9;

  std::vector<int> end;  // the nodes at the far end, as a mouse would pick them
  for (int i = 0; i < body.num_nodes(); ++i)
    if (body.position(i)[0] > 0.6 - 1e-6) end.push_back(i);
  const double before = body.position(end[0])[2];
  body.grab(end, {0.0, 0.0, 0.5});  // lifted at 0.5 m/s
  frames(body, 60, "one end grabbed and lifted");
  const bool lifted = body.position(end[0])[2] > before + 0.25;
  body.release();
  frames(body, 90, "released");
  const bool landed_again = !body.floor_contacts().empty() && lowest(body) >= floor - 1e-9;

  const femcourse::DeformationStatus watch = body.check_deformation();
  std::printf("deformation: largest stretch %.3f, %d inverted: %s\n", watch.largest_stretch,
              watch.inverted_elements, watch.plausible ? "plausible" : "blown up");
  const bool ok = landed && lifted && landed_again && watch.plausible;
  std::printf("%s\n",
              ok ? "PASS: landed, lifted, released and landed again" : "FAIL: see the lines above");
  return ok ? 0 : 1;
}
