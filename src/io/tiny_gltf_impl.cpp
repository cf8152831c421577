// io/tiny_gltf_impl.cpp: TinyGLTF's implementation (Debian's libtinygltf-dev ships it as a header),
// compiled once with the options of io/gltf_document.hpp: no stb_image (images go through
// softrast's own decoders), no file system of its own (softrast's checked callbacks), external
// images left to the loader. Compiled inside the library so the fuzzer instruments it too.
// Its writer (unused here) needs <fstream> even when TINYGLTF_NO_FS leaves it out.
#include <fstream>

#define TINYGLTF_IMPLEMENTATION
#include "io/gltf_document.hpp"
