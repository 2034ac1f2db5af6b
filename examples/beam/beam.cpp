// A cantilever beam made from arrays, clamped at x = 0, swinging down under gravity for
// a second: the deflection of its tip (the node at x = L, y = W, z = H) is printed.
// `beam --msh FILE` also writes the body as a gmsh file, for fem_sim to run the same body.
#include <array>
#include <cstdio>
#include <cstring>
#include <femcourse/simulator.hpp>
#include <utility>

int main(int argc, char** argv) {
  const int nx = 10, ny = 2, nz = 2;  // hexahedra along the beam's length, width and height
  const double L = 1.0, W = 0.1, H = 0.1;
  const auto node = [&](int i, int j, int k) { return (i * (ny + 1) + j) * (nz + 1) + k; };
  femcourse::BodyDescription beam;
  beam.youngs_modulus = 1e6;
  for (int i = 0; i <= nx; ++i)
    for (int j = 0; j <= ny; ++j)
      for (int k = 0; k <= nz; ++k) {
        beam.rest_positions.insert(beam.rest_positions.end(), {L * i / nx, W * j / ny, H * k / nz});
        if (i == 0) beam.constraints.push_back({node(i, j, k)});  // Kind::Fixed: clamped
      }
  // Each hexahedron as six tetrahedra around its diagonal (Kuhn's split), positively oriented.
  const std::array<std::array<int, 3>, 6> axes{
      {{0, 1, 2}, {1, 2, 0}, {2, 0, 1}, {0, 2, 1}, {2, 1, 0}, {1, 0, 2}}};
  for (int i = 0; i < nx; ++i)
    for (int j = 0; j < ny; ++j)
      for (int k = 0; k < nz; ++k)
        for (int p = 0; p < 6; ++p) {
          std::array<int, 3> c{i, j, k};
          int tet[4] = {node(i, j, k), 0, 0, 0};
          for (int s = 0; s < 3;
               ++s) {  // a path along the edges from corner (i,j,k) to the far one
            ++c[axes[p][s]];
            tet[s + 1] = node(c[0], c[1], c[2]);
          }
          if (p >= 3) std::swap(tet[2], tet[3]);  // odd permutations turn the other way
          beam.tetrahedra.insert(beam.tetrahedra.end(), tet, tet + 4);
        }
  if (argc == 3 && std::strcmp(argv[1], "--msh") == 0) {  // gmsh's format 2.2, node i as tag i+1
    FILE* f = std::fopen(argv[2], "w");
    if (!f) {
      std::perror(argv[2]);
      return 1;
    }
    const std::size_t n = beam.rest_positions.size() / 3, m = beam.tetrahedra.size() / 4;
    std::fprintf(f, "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n%zu\n", n);
    for (std::size_t i = 0; i < n; ++i)
      std::fprintf(f, "%zu %.17g %.17g %.17g\n", i + 1, beam.rest_positions[3 * i],
                   beam.rest_positions[3 * i + 1], beam.rest_positions[3 * i + 2]);
    std::fprintf(f, "$EndNodes\n$Elements\n%zu\n", m);
    for (std::size_t e = 0; e < m; ++e)
      std::fprintf(f, "%zu 4 2 0 1 %d %d %d %d\n", e + 1, beam.tetrahedra[4 * e] + 1,
                   beam.tetrahedra[4 * e + 1] + 1, beam.tetrahedra[4 * e + 2] + 1,
                   beam.tetrahedra[4 * e + 3] + 1);
    std::fprintf(f, "$EndElements\n");
    std::fclose(f);
  }
  femcourse::Body body(beam);  // the last chapter's stepper
  for (int step = 0; step < 100; ++step) body.step();
  const int tip = node(nx, ny, nz);
  std::printf("chapter %s, %d steps: tip node %d deflection %.17g m (%d CG iterations)\n",
              body.chapter().c_str(), 100, tip, body.position(tip)[2] - H,
              body.profile().iterations);
}
