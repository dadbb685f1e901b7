// Shared by the fuzz targets (docs/fuzz.md): each target defines
// LLVMFuzzerTestOneInput(), built with libFuzzer (scripts/fuzz.sh, clang) or
// with replay_main.cpp into a program that CTest runs over the committed
// corpus (seeds and every finding's input).
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size);

namespace bims::fuzz
{
/** A folder of this process's own, made once (under $TMPDIR or /tmp). */
const std::string& scratchDir();
/** Writes \a size bytes to scratchDir()/name (truncated first); returns
 * the path. */
std::string writeFile(const std::string& name, const uint8_t* data,
                      size_t size);
/** Splits \a data into at most \a n parts at the separator line "\n--\n"
 * (a text input for several files). */
std::vector<std::string> splitParts(const uint8_t* data, size_t size, size_t n);
}  // namespace bims::fuzz
