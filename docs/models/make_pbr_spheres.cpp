// docs/models/make_pbr_spheres.cpp: writes pbr_spheres.glb, the README's PBR example: 5 x 5
// spheres of a gold base colour, roughness 0 to 1 from left to right, metallic 0 to 1 from top to
// bottom, with the tests' glTF writer (tests/gltf_util.hpp). Build and run from the repository:
//   g++ -std=c++20 -Iinclude -Itests docs/models/make_pbr_spheres.cpp -o /tmp/make_pbr_spheres \
//     build/release/libsoftrast.a $(pkg-config --libs spng stb) -ljpeg -lz -lpthread
//   /tmp/make_pbr_spheres docs/models/pbr_spheres.glb
#include <cstdio>
#include <fstream>

#include "gltf_util.hpp"

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: make_pbr_spheres OUT.glb\n");
    return 2;
  }
  std::ofstream(argv[1], std::ios::binary)
      << softrast::test::as_glb(softrast::test::sphere_grid(5, 5, 1.0f, 0.78f, 0.34f));
  return 0;
}
