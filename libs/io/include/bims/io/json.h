// The one home of JSON writing: every JSON file bims writes (bims-run's
// metrics.json, bims-eval's reports) is built as a Json value (nlohmann's
// JSON library, keys in insertion order) and written by writeJsonFile, so
// quotes, backslashes and control characters in any text are escaped; and
// of reading one back (readJsonFile).
#pragma once

#include <nlohmann/json.hpp>

#include <string>

namespace bims
{
using Json = nlohmann::ordered_json;

/** \a v as a JSON number: rounded to \a decimals after the point (%.*f), or
 * to 9 significant digits with decimals < 0 (%.9g); null if not finite. */
Json jsonNumber(double v, int decimals = -1);

/** The text of \a j: indented by 2, bytes that are not UTF-8 replaced
 * (U+FFFD), a newline at the end. */
std::string jsonText(const Json& j);

/** The text of \a j on one line (JSON lines), no newline. */
std::string jsonLine(const Json& j);

/** Writes jsonText(j) to \a path (writeFileAtomically: complete or not at
 * all; throws naming the file). */
void writeJsonFile(const std::string& path, const Json& j);

/** The JSON value in the file \a path; throws std::runtime_error "PATH:
 * cannot open" or "PATH: not JSON: WHY". */
Json readJsonFile(const std::string& path);

}  // namespace bims
