// Every program's --frames A:B (3D-scan indices, inclusive): parsed and
// checked against the inputs before any work.
#pragma once

#include <bims/source/frame_source.h>

#include <string>
#include <vector>

namespace bims::apps
{
/** A program's --frames option: \a text "" (not given) is the whole input;
 * otherwise parsed (source::FrameRange::parse) and checked against the
 * inputs (source::checkFrameRangeInInputs). Their errors, bad text or a
 * range beyond the inputs, are thrown as a UsageError with the same
 * message. */
source::FrameRange frameRangeOption(const std::string& text,
                                    const std::vector<std::string>& rawlogs,
                                    const std::string& rgbdLabel);

}  // namespace bims::apps
