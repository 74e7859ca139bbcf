// ./tissue solve SCENE.yaml [--out OUT.vtk] [--stats OUT.json] [--backend cpu|gl]
// (SPEC section 4). Placeholder until the pipeline lands.
#include <cstdio>
int main() {
  std::fprintf(stderr, "tissue solve: not implemented yet\n");
  return 2;
}
