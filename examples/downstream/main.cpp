// Loads a URDF robot on a free-floating base and prints G* at a contact link.
#include <iostream>
#include <kdl_space/algorithm/free_floating_solver.hpp>
#include <kdl_space/parsers/urdf/urdf_loader.hpp>

int main(int argc, char** argv) {
  if (argc != 3) { std::cerr << "usage: print_g_star ROBOT.urdf CONTACT_LINK\n"; return 2; }
  try {
    auto model = std::make_shared<const kdl_space::FloatingModel>(kdl_space::loadUrdfFile(argv[1]));
    kdl_space::FreeFloatingSolver solver(model);
    kdl_space::State state(*model);                  // base at the origin, joints at 0
    kdl_space::Matrix6d G_star;
    if (solver.compute(state) != 0 || solver.G_star(model->contact(argv[2]), G_star) != 0) return 3;
    std::cout << "G* at " << argv[2] << " (world frame, twist per impulse):\n" << G_star << "\n";
  } catch (const kdl_space::ModelError& e) {
    std::cerr << e.what() << "\n";
    return 3;
  }
}
