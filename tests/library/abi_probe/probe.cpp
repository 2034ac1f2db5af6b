// Builds one tetrahedron and steps it: what reads a BodyDescription through the library.
#include <femcourse/simulator.hpp>
#include <iostream>

int main() {
  femcourse::BodyDescription d;
  d.rest_positions = {0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1};
  d.tetrahedra = {0, 1, 2, 3};
  d.constraints = {{0}};
  femcourse::Body body(d);
  body.step();
  std::cout << "stepped to t = " << body.time() << " s\n";
}
