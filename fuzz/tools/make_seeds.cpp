// fuzz/tools/make_seeds.cpp: writes the seed corpora of the fuzz targets (small, valid files of
// every variant each decoder handles) into fuzz/corpus/<target>/. Run by fuzz/tools/make_seeds.sh;
// the output is committed, so this runs only when the seeds change.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <jpeglib.h>  // after <cstdio>: it needs size_t and FILE
#include <spng.h>

namespace fs = std::filesystem;
using Bytes = std::vector<uint8_t>;

fs::path g_root;

void put(const std::string& target, const std::string& name, const Bytes& data) {
  fs::create_directories(g_root / target);
  std::ofstream(g_root / target / name, std::ios::binary)
      .write(reinterpret_cast<const char*>(data.data()), std::streamsize(data.size()));
}
void put(const std::string& target, const std::string& name, const std::string& text) {
  put(target, name, Bytes(text.begin(), text.end()));
}

Bytes png(uint32_t w, uint32_t h, uint8_t depth, uint8_t type, const Bytes& pixels,
          uint8_t interlace = 0, spng_plte* plte = nullptr, spng_trns* trns = nullptr) {
  spng_ctx* ctx = spng_ctx_new(SPNG_CTX_ENCODER);
  spng_set_option(ctx, SPNG_ENCODE_TO_BUFFER, 1);
  spng_ihdr ihdr{w, h, depth, type, 0, 0, interlace};
  spng_set_ihdr(ctx, &ihdr);
  if (plte) spng_set_plte(ctx, plte);
  if (trns) spng_set_trns(ctx, trns);
  int e = spng_encode_image(ctx, pixels.data(), pixels.size(), SPNG_FMT_PNG, SPNG_ENCODE_FINALIZE);
  if (e) std::fprintf(stderr, "spng: %s\n", spng_strerror(e));
  size_t len = 0;
  int err = 0;
  auto* buf = static_cast<uint8_t*>(spng_get_png_buffer(ctx, &len, &err));
  Bytes out(buf, buf + len);
  std::free(buf);
  spng_ctx_free(ctx);
  return out;
}

Bytes ramp(size_t n, int mul = 37) {
  Bytes b(n);
  for (size_t i = 0; i < n; ++i) b[i] = uint8_t(i * mul + 11);
  return b;
}

Bytes jpeg(int w, int h, int components, bool progressive, int restart, int h_samp) {
  jpeg_compress_struct c{};
  jpeg_error_mgr err{};
  c.err = jpeg_std_error(&err);
  jpeg_create_compress(&c);
  unsigned char* out = nullptr;
  unsigned long size = 0;
  jpeg_mem_dest(&c, &out, &size);
  c.image_width = w;
  c.image_height = h;
  c.input_components = components;
  c.in_color_space = components == 1 ? JCS_GRAYSCALE : JCS_RGB;
  jpeg_set_defaults(&c);
  jpeg_set_quality(&c, 75, TRUE);
  if (components == 3) c.comp_info[0].h_samp_factor = c.comp_info[0].v_samp_factor = h_samp;
  if (progressive) jpeg_simple_progression(&c);
  c.restart_interval = restart;
  jpeg_start_compress(&c, TRUE);
  Bytes pixels = ramp(size_t(w) * h * components, 7);
  for (int y = 0; y < h; ++y) {
    JSAMPROW row = pixels.data() + size_t(y) * w * components;
    jpeg_write_scanlines(&c, &row, 1);
  }
  jpeg_finish_compress(&c);
  Bytes b(out, out + size);
  jpeg_destroy_compress(&c);
  std::free(out);
  return b;
}

// TGA: image type 1 (colour-mapped), 2 (true colour), 3 (grey), +8 for RLE; descriptor bit 5 set
// for top-down rows.
Bytes tga(int type, int w, int h, int bpp, bool top_down, const Bytes& body, int alpha_bits = 0,
          int map_length = 0, int map_bpp = 0) {
  Bytes b = {0,
             uint8_t(map_length ? 1 : 0),
             uint8_t(type),
             0,
             0,
             uint8_t(map_length & 255),
             uint8_t(map_length >> 8),
             uint8_t(map_bpp),
             0,
             0,
             0,
             0,
             uint8_t(w & 255),
             uint8_t(w >> 8),
             uint8_t(h & 255),
             uint8_t(h >> 8),
             uint8_t(bpp),
             uint8_t(alpha_bits | (top_down ? 0x20 : 0))};
  b.insert(b.end(), body.begin(), body.end());
  return b;
}

void image_seeds() {
  put("png", "rgba_3x2.png", png(3, 2, 8, 6, ramp(24)));
  put("png", "rgb_5x3.png", png(5, 3, 8, 2, ramp(45)));
  put("png", "grey_4x4.png", png(4, 4, 8, 0, ramp(16)));
  put("png", "grey_alpha_2x2.png", png(2, 2, 8, 4, ramp(8)));
  put("png", "grey1_9x2.png", png(9, 2, 1, 0, ramp(4)));
  put("png", "rgb16_2x2.png", png(2, 2, 16, 2, ramp(24)));
  put("png", "rgba16_1x3.png", png(1, 3, 16, 6, ramp(24)));
  put("png", "interlaced_9x9.png", png(9, 9, 8, 2, ramp(243), 1));
  spng_plte plte{};
  plte.n_entries = 4;
  for (int i = 0; i < 4; ++i) plte.entries[i] = {uint8_t(60 * i), uint8_t(255 - 60 * i), 9, 0};
  spng_trns trns{};
  trns.n_type3_entries = 2;
  trns.type3_alpha[0] = 0;
  trns.type3_alpha[1] = 128;
  put("png", "palette2_5x3.png",
      png(5, 3, 2, 3, Bytes{0x1b, 0x40, 0xe4, 0x10, 0x93, 0x00}, 0, &plte, &trns));

  put("tga", "rgb_bottom_up_3x2.tga", tga(2, 3, 2, 24, false, ramp(18)));
  put("tga", "rgba_top_down_2x2.tga", tga(2, 2, 2, 32, true, ramp(16), 8));
  put("tga", "grey_3x3.tga", tga(3, 3, 3, 8, false, ramp(9)));
  put("tga", "rgb16_2x1.tga", tga(2, 2, 1, 16, false, ramp(4)));
  // RLE: a run packet of 3 pixels, a raw packet of 2, a run of 1 (6 pixels, 3x2).
  put("tga", "rle_rgb_3x2.tga",
      tga(10, 3, 2, 24, false, Bytes{0x82, 1, 2, 3, 0x01, 4, 5, 6, 7, 8, 9, 0x80, 10, 11, 12}));
  put("tga", "rle_grey_top_down_4x1.tga", tga(11, 4, 1, 8, true, Bytes{0x81, 50, 0x01, 7, 9}));
  put("tga", "rle_rgba_2x2.tga", tga(10, 2, 2, 32, false, Bytes{0x83, 1, 2, 3, 4}, 8));
  Bytes mapped = {10, 20, 30, 40, 50, 60, 70, 80, 90, 0, 1, 2, 2, 1, 0};  // 3 BGR entries, 6 px
  put("tga", "colormapped_3x2.tga", tga(1, 3, 2, 8, false, mapped, 0, 3, 24));

  put("jpeg", "grey_8x8.jpg", jpeg(8, 8, 1, false, 0, 1));
  put("jpeg", "rgb_444_9x7.jpg", jpeg(9, 7, 3, false, 0, 1));
  put("jpeg", "rgb_420_17x9.jpg", jpeg(17, 9, 3, false, 0, 2));
  put("jpeg", "progressive_16x16.jpg", jpeg(16, 16, 3, true, 0, 2));
  put("jpeg", "restart_24x8.jpg", jpeg(24, 8, 3, false, 1, 1));
  put("jpeg", "progressive_grey_8x9.jpg", jpeg(8, 9, 1, true, 0, 1));
}

void obj_seeds() {
  const std::string mtl_sep = "\n#--mtl--\n", tex_sep = "\n#--tex--\n";
  put("obj", "triangle.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
  put("obj", "quad_uv_normals.obj",
      "# a quad\nv -1 -1 0\nv 1 -1 0\nv 1 1 0\nv -1 1 0\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\n"
      "vn 0 0 1\ns 1\ng quad\no q\nf 1/1/1 2/2/1 3/3/1 4/4/1\n");
  put("obj", "negative_indices.obj",
      "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 1e-3\nf -4 -3 -2\nf -4//-1 -2 -1\nvn 0 0 1\n"
      "f 1//1 3//1 4//1\n");
  put("obj", "crlf_pentagon.obj",
      "v 1 0 0\r\nv 0.3 0.95 0\r\nv -0.8 0.58 0\r\nv -0.8 -0.58 0\r\nv 0.3 -0.95 0\r\n"
      "f 1 2 3 4 5\r\n");
  put("obj", "materials.obj",
      "mtllib model.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nvt 0 0\nvt 1 0\nvt 0 1\nvt 1 1\n"
      "usemtl red\nf 1/1 2/2 3/3\nusemtl textured\nf 2/2 4/4 3/3\nusemtl missing\nf 1 2 4\n" +
          mtl_sep + "newmtl red\nKd 1 0 0\nNs 10\n\nnewmtl textured\nKd 1 1 1\nmap_Kd tex.png\n" +
          tex_sep);
  Bytes texture = tga(2, 2, 2, 24, false, ramp(12));
  std::string with_texture =
      "mtllib model.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 0 1\n"
      "usemtl t\nf 1/1 2/2 3/3\n" +
      mtl_sep + "newmtl t\nKd 0.5 0.5 0.5\nmap_Kd -o 0 0 tex.png\n" + tex_sep;
  with_texture.append(texture.begin(), texture.end());
  put("obj", "textured_tga.obj", with_texture);
  put("obj", "numbers.obj",
      "v 1e3 -2.5E-3 +4\nv .5 -.5 0.\nv 0x10 1 1\nv 3 4 5 1.0\nvt 0.5 0.5 0\nvn 1 0 0\n"
      "f 1/1/1 2/1/1 3/1/1 4/1/1\nl 1 2\np 3\n");
}

void cli_seeds() {
  put("cli_args", "demo", "render\n-o\nout.png\n");
  put("cli_args", "model_flags",
      "model.obj\n--size\n64x48\n--shader\ngouraud\n--wireframe\n--eye\n0,1,3\n--target\n0,0,0\n"
      "--fov\n45\n--near\n0.1\n--far\n100\n");
  put("cli_args", "ortho_state",
      "m.obj\n--ortho\n-1,1,-1,1\n--cull\nnone\n--front-face\ncw\n--depth\nlequal\n--blend\n"
      "alpha\n--alpha\n0.5\n--raster\nscanline\n--threads\n2\n--reference-path\n");
  put("cli_args", "texture",
      "m.obj\n--shader\ntexture\n--texture\nt.png\n--filter\ntrilinear\n--wrap\nmirror\n--color\n"
      "1,0.5,0\n--light\n0,1,0\n-q\n");
  put("cli_args", "frames", "m.obj\n--frames\n10\n-o\nx.tga\n");
  put("cli_args", "bad_size", "--size\n16384x16384\n");
  put("cli_args", "help", "--help\n");
}

void put_floats(Bytes& b, std::initializer_list<float> fs) {
  for (float f : fs) {
    uint8_t p[4];
    std::memcpy(p, &f, 4);
    b.insert(b.end(), p, p + 4);
  }
}

void grid_vertex(Bytes& b, int x_fx8, int y_fx8, int z, int w_choice, int v0, int v1) {
  b.push_back(uint8_t(x_fx8 & 255));
  b.push_back(uint8_t((x_fx8 >> 8) & 255));
  b.push_back(uint8_t(y_fx8 & 255));
  b.push_back(uint8_t((y_fx8 >> 8) & 255));
  b.push_back(uint8_t(z));
  b.push_back(uint8_t(w_choice));
  b.push_back(uint8_t(v0));
  b.push_back(uint8_t(v1));
}

void geometry_seeds() {
  const float nan = std::nanf(""), inf = INFINITY;
  Bytes a = {0x00, 0x00};  // raw floats, edge equations, scalar, binned, full scissor
  put_floats(a, {-0.5f, -0.5f, 0, 1, 0, 0, 0.5f, -0.5f, 0, 1, 1, 0, 0, 0.5f, 0, 1, 0, 1});
  put("geometry", "raw_one_triangle", a);
  Bytes b = {0x0b, 0x25};  // raw, scanline, wide, reference counting, sub-scissor
  put_floats(b, {-2,    -2,     -3, 1,      0, 0, 3,      -1,    0.5f, -1, 1,   0,
                 0,     4,      2,  0.5f,   0, 1,  // w < 0
                 nan,   0,      0,  1,      0, 0, 0,      0,     0,    1,  0,   0,
                 1,     1,      0,  1,      0, 0,  // NaN
                 1e38f, -1e38f, 0,  1e-38f, 0, 0, -1e30f, 1e30f, 0,    1,  0,   0,
                 0,     0,      0,  1e-45f, 0, 0, inf,    1,     0,    1,  0,   0,
                 0,     -inf,   0,  1,      0, 0, 1,      1,     1,    1,  inf, nan});
  put("geometry", "raw_hostile", b);
  Bytes c = {0x04 | 0x10, 0x00};  // grid, back-face culled two-path draw
  // Two triangles sharing an edge through pixel centres, a third crossing the near plane.
  grid_vertex(c, -8 * 256 + 128, -8 * 256 + 128, 0, 0, 0, 0);
  grid_vertex(c, 8 * 256 + 128, -8 * 256 + 128, 10, 0, 255, 0);
  grid_vertex(c, -8 * 256 + 128, 8 * 256 + 128, 20, 0, 0, 255);
  grid_vertex(c, 8 * 256 + 128, -8 * 256 + 128, 10, 0, 255, 0);
  grid_vertex(c, 8 * 256 + 128, 8 * 256 + 128, -30, 0, 255, 255);
  grid_vertex(c, -8 * 256 + 128, 8 * 256 + 128, 20, 0, 0, 255);
  grid_vertex(c, -20 * 256, 0, 127, 1, 9, 9);
  grid_vertex(c, 30 * 256, 5 * 256, -127, 2, 9, 9);
  grid_vertex(c, 0, 30 * 256, 0, 5, 9, 9);
  put("geometry", "grid_shared_edge_and_clipped", c);
  Bytes d = {0x04 | 0x02 | 0x40 | 0x80, 0xff};  // grid, wide, two threads, bias, small scissor
  grid_vertex(d, -100 * 256, -100 * 256, 0, 3, 1, 2);
  grid_vertex(d, 120 * 256, -90 * 256, 0, 6, 3, 4);
  grid_vertex(d, 0, 127 * 256, 0, 7, 5, 6);
  put("geometry", "grid_large_tiny_w", d);
}

int main(int argc, char** argv) {
  g_root = argc > 1 ? argv[1] : "fuzz/corpus";
  image_seeds();
  obj_seeds();
  cli_seeds();
  geometry_seeds();
  return 0;
}
