// The CRC-32 of every entry of a ZIP archive, checked against its directory. Why: torch's weights
// files are ZIP archives, and libtorch's reader does not check the checksums (its miniz is built
// without them): a model whose bytes were damaged in a copy loaded and answered other figures
// (the sign bit of every float16 flipped: RMSE 2.72 where the intact file read 2.66, exit 0).
#ifndef CLOTHWIND_LEARN_ZIP_CHECKSUMS_H_
#define CLOTHWIND_LEARN_ZIP_CHECKSUMS_H_

#include <filesystem>

namespace clothwind::learn {

// Checks every stored (uncompressed) entry of the ZIP archive at `path` against the CRC-32 its
// central directory records (ZIP64 sizes and offsets included). Entries compressed otherwise are
// left to their reader (torch writes none).
// Throws std::runtime_error naming the file and, for a damaged entry, the entry: "<path>: entry
// <name> fails its checksum ..."; and for an archive whose directory cannot be read ("not a ZIP
// archive", "cut short").
void VerifyZipChecksums(const std::filesystem::path& path);

}  // namespace clothwind::learn

#endif  // CLOTHWIND_LEARN_ZIP_CHECKSUMS_H_
