// A view-factor matrix as NumPy's CSR archive: the .npz that scipy.sparse.save_npz writes and
// scipy.sparse.load_npz reads (a zip of .npy arrays), for scripts. Kept apart from
// factors_format.hpp because it needs libzip; the test suite compiles it too.
#pragma once

#include <filesystem>

#include "radiosity/form_factors.hpp"

namespace cli {

/// Writes `m` to `path` as scipy.sparse's CSR archive: members data.npy (float32 factors),
/// indices.npy (int32 columns), indptr.npy (int64 row offsets), shape.npy (int64 [rows, rows])
/// and format.npy (b'csr'), plus, beside them, ids.npy (uint32: the polygon, element or group
/// id of each row), area.npy, sky.npy and sky_standard_error.npy (float64 per row) and, when the estimator states one,
/// row_standard_error.npy; load_npz reads the first five and ignores the rest, numpy.load
/// reads all. Stored uncompressed (the factors do not compress much, and writing stays a
/// copy). Throws radiosity::Error{io_error} naming the file when it cannot be written.
void write_npz(const radiosity::ViewFactorMatrix& m, const std::filesystem::path& path);

}  // namespace cli
