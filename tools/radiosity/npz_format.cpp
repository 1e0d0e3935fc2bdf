// NumPy's .npz CSR archive (npz_format.hpp).
// Based on: NumPy Enhancement Proposal 1, "A simple file format for NumPy arrays" (the .npy
// header: magic, version 1.0, a Python dict literal padded so the data starts at a multiple of
// 64 bytes); SciPy's scipy.sparse.save_npz / load_npz (the member names and the 'format' entry).
#include "npz_format.hpp"

#include <zip.h>

#include <cstdint>
#include <cstring>
#include <memory>
#include <string>
#include <vector>

namespace cli {
namespace {

/// One .npy file: a version 1.0 header for a C-ordered array of `descr` and `shape`, then the
/// raw little-endian data.
std::string npy(const char* descr, const std::string& shape, const void* data, std::size_t bytes) {
  std::string dict = std::string("{'descr': '") + descr + "', 'fortran_order': False, 'shape': " + shape + ", }";
  // Magic (6) + version (2) + header length (2) + dict + padding + '\n' = a multiple of 64.
  const std::size_t unpadded = 10 + dict.size() + 1;
  dict.append((64 - unpadded % 64) % 64, ' ');
  dict += '\n';
  std::string out("\x93NUMPY\x01\x00", 8);
  const std::uint16_t length = static_cast<std::uint16_t>(dict.size());
  out += static_cast<char>(length & 0xff);
  out += static_cast<char>(length >> 8);
  out += dict;
  out.append(static_cast<const char*>(data), bytes);
  return out;
}

template <typename T>
std::string npy_vector(const char* descr, const std::vector<T>& v) {
  return npy(descr, "(" + std::to_string(v.size()) + ",)", v.data(), v.size() * sizeof(T));
}

}  // namespace

void write_npz(const radiosity::ViewFactorMatrix& m, const std::filesystem::path& path) {
  static_assert(sizeof(float) == 4 && sizeof(double) == 8, "npy descriptors below");
  const std::uint32_t probe = 1;
  unsigned char first = 0;
  std::memcpy(&first, &probe, 1);
  if (first != 1)
    throw radiosity::Error(radiosity::ErrorCode::io_error, "write_npz: big-endian machines are not supported");

  std::vector<std::pair<std::string, std::string>> members;
  members.emplace_back("data.npy", npy_vector("<f4", m.values));
  std::vector<std::int32_t> indices(m.columns.begin(), m.columns.end());
  members.emplace_back("indices.npy", npy_vector("<i4", indices));
  std::vector<std::int64_t> indptr(m.row_offsets.begin(), m.row_offsets.end());
  members.emplace_back("indptr.npy", npy_vector("<i8", indptr));
  const std::vector<std::int64_t> shape{static_cast<std::int64_t>(m.rows()), static_cast<std::int64_t>(m.rows())};
  members.emplace_back("shape.npy", npy_vector("<i8", shape));
  members.emplace_back("format.npy", npy("|S3", "()", "csr", 3));
  members.emplace_back("ids.npy", npy_vector("<u4", m.ids));
  members.emplace_back("area.npy", npy_vector("<f8", m.area));
  members.emplace_back("sky.npy", npy_vector("<f8", m.sky));
  members.emplace_back("sky_standard_error.npy", npy_vector("<f8", m.sky_standard_error));
  if (!m.row_standard_error.empty()) members.emplace_back("row_standard_error.npy", npy_vector("<f8", m.row_standard_error));

  auto fail = [&](const std::string& why) {
    throw radiosity::Error(radiosity::ErrorCode::io_error, "cannot write '" + path.string() + "': " + why);
  };
  int error = 0;
  zip_t* archive = zip_open(path.string().c_str(), ZIP_CREATE | ZIP_TRUNCATE, &error);
  if (!archive) {
    zip_error_t e;
    zip_error_init_with_code(&e, error);
    const std::string why = zip_error_strerror(&e);
    zip_error_fini(&e);
    fail(why);
  }
  for (const auto& [name, bytes] : members) {
    // libzip reads the buffers when the archive is closed: they live in `members` until then.
    zip_source_t* source = zip_source_buffer(archive, bytes.data(), bytes.size(), 0);
    if (!source) fail(zip_strerror(archive));
    const zip_int64_t index = zip_file_add(archive, name.c_str(), source, ZIP_FL_OVERWRITE);
    if (index < 0) {
      zip_source_free(source);
      const std::string why = zip_strerror(archive);
      zip_discard(archive);
      fail(why);
    }
    zip_set_file_compression(archive, static_cast<zip_uint64_t>(index), ZIP_CM_STORE, 0);
  }
  if (zip_close(archive) != 0) {
    const std::string why = zip_strerror(archive);
    zip_discard(archive);
    fail(why);
  }
}

}  // namespace cli
