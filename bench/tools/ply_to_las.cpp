// ply_to_las IN.ply OUT.las: a point cloud as LAS 1.2, point format 2 (positions at 0.1 mm,
// colours as 16 bits), written from the ASPRS LAS 1.2 specification, in constant memory (two
// passes over the input: bounds, then records). For measuring converters that read only LAS
// (PotreeConverter) on the very points Pointillist converts; not part of the program.
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <limits>
#include <string>
#include <vector>

#include "pointillist/io/point_stream.hpp"

namespace {

template <class T>
void put(std::string& out, T value) {
  char bytes[sizeof(T)];
  std::memcpy(bytes, &value, sizeof(T));
  out.append(bytes, sizeof(T));
}

void put_text(std::string& out, const char* text, std::size_t size) {
  std::string field(text);
  field.resize(size, '\0');
  out += field;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 3) {
    std::fprintf(stderr, "usage: ply_to_las IN.ply OUT.las\n");
    return 2;
  }
  try {
    auto in = pointillist::open_point_stream(argv[1]);
    const std::uint64_t n = in->info().point_count;
    if (n > std::numeric_limits<std::uint32_t>::max()) {
      std::fprintf(stderr, "ply_to_las: %llu points do not fit LAS 1.2's 32-bit count\n",
                   (unsigned long long)n);
      return 1;
    }
    double lo[3] = {INFINITY, INFINITY, INFINITY}, hi[3] = {-INFINITY, -INFINITY, -INFINITY};
    pointillist::PointSet batch;
    while (in->read(batch, 1 << 20)) {
      for (const auto& p : batch.positions) {
        for (int a = 0; a < 3; ++a) {
          lo[a] = std::min(lo[a], double(p[a]));
          hi[a] = std::max(hi[a], double(p[a]));
        }
      }
    }
    const double scale = 0.0001;
    const double offset[3] = {std::floor(lo[0]), std::floor(lo[1]), std::floor(lo[2])};
    std::string h;
    put_text(h, "LASF", 4);
    put<std::uint16_t>(h, 0);  // file source id
    put<std::uint16_t>(h, 0);  // global encoding
    put_text(h, "", 16);       // project GUID
    put<std::uint8_t>(h, 1);
    put<std::uint8_t>(h, 2);
    put_text(h, "pointillist bench", 32);
    put_text(h, "ply_to_las", 32);
    put<std::uint16_t>(h, 1);     // day of year
    put<std::uint16_t>(h, 2026);  // year
    put<std::uint16_t>(h, 227);   // header size
    put<std::uint32_t>(h, 227);   // offset to point data
    put<std::uint32_t>(h, 0);     // variable length records
    put<std::uint8_t>(h, 2);      // point data format
    put<std::uint16_t>(h, 26);    // record length
    put<std::uint32_t>(h, std::uint32_t(n));
    put<std::uint32_t>(h, std::uint32_t(n));  // points by return: all first returns
    for (int r = 1; r < 5; ++r) put<std::uint32_t>(h, 0);
    for (int a = 0; a < 3; ++a) put<double>(h, scale);
    for (int a = 0; a < 3; ++a) put<double>(h, offset[a]);
    for (int a = 0; a < 3; ++a) {
      put<double>(h, hi[a]);
      put<double>(h, lo[a]);
    }
    if (h.size() != 227) throw std::runtime_error("header is not 227 bytes");
    std::FILE* out = std::fopen(argv[2], "wb");
    if (!out) throw std::runtime_error(std::string(argv[2]) + ": cannot create");
    std::fwrite(h.data(), 1, h.size(), out);
    in->rewind();
    std::string records;
    while (const std::size_t got = in->read(batch, 1 << 20)) {
      records.clear();
      for (std::size_t i = 0; i < got; ++i) {
        for (int a = 0; a < 3; ++a) {
          put<std::int32_t>(records,
                            std::int32_t(std::lround((batch.positions[i][a] - offset[a]) / scale)));
        }
        put<std::uint16_t>(records, 0);   // intensity
        put<std::uint8_t>(records, 0x09);  // return 1 of 1
        put<std::uint8_t>(records, 1);     // class: unclassified
        put<std::int8_t>(records, 0);      // scan angle
        put<std::uint8_t>(records, 0);     // user data
        put<std::uint16_t>(records, 0);    // point source
        const pointillist::Rgb8 c =
            batch.colors.empty() ? pointillist::Rgb8{180, 180, 180} : batch.colors[i];
        put<std::uint16_t>(records, std::uint16_t(c.r * 257));
        put<std::uint16_t>(records, std::uint16_t(c.g * 257));
        put<std::uint16_t>(records, std::uint16_t(c.b * 257));
      }
      if (std::fwrite(records.data(), 1, records.size(), out) != records.size()) {
        throw std::runtime_error(std::string(argv[2]) + ": cannot write (disk full?)");
      }
    }
    if (std::fclose(out) != 0) throw std::runtime_error(std::string(argv[2]) + ": cannot close");
  } catch (const std::exception& e) {
    std::fprintf(stderr, "ply_to_las: %s\n", e.what());
    return 1;
  }
  return 0;
}
