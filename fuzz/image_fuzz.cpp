// fuzz/image_fuzz.cpp: decode_image on arbitrary bytes (the PNG, TGA and JPEG targets differ only
// in their seed corpora and dictionaries; the decoder tells the format by content).
#include <string>

#include "fuzz_entries.hpp"
#include "softrast/image.hpp"

namespace softrast::fuzz {

int fuzz_image(const uint8_t* data, size_t size) {
  Result<Image> image = decode_image(data, size, "fuzz.img");
  if (!image) {
    const std::string& m = image.status().message();
    SOFTRAST_FUZZ_REQUIRE(!m.empty(), "decode_image failed without a message");
    SOFTRAST_FUZZ_REQUIRE(m.find("fuzz.img") != std::string::npos,
                          "error does not name the file: " + m);
    return 0;
  }
  SOFTRAST_FUZZ_REQUIRE(image->width >= 1 && image->height >= 1, "decoded an empty image");
  SOFTRAST_FUZZ_REQUIRE(image->width <= kMaxImageSize && image->height <= kMaxImageSize,
                        "decoded image beyond kMaxImageSize");
  SOFTRAST_FUZZ_REQUIRE(int64_t(image->width) * image->height <= kMaxImagePixels,
                        "decoded image beyond kMaxImagePixels");
  SOFTRAST_FUZZ_REQUIRE(image->rgba.size() == size_t(image->width) * size_t(image->height) * 4,
                        "pixel buffer size does not match width x height");
  // Touch every byte, so an uninitialised buffer shows up under MemorySanitizer-like tools and a
  // wrong size under ASan.
  unsigned sum = 0;
  for (uint8_t b : image->rgba) sum += b;
  (void)sum;
  return 0;
}

}  // namespace softrast::fuzz
