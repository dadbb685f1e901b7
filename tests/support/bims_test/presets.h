// The paper's literal model (config/paper.ini) for tests written against it:
// the built-in defaults are config/default.ini's tuned model.
#pragma once

#include <mrpt/config/CConfigFile.h>

#include <string>

namespace bims::test
{
/** config/paper.ini of the source tree. */
inline std::string paperIni()
{
	return std::string(BIMS_SOURCE_DIR) + "/config/paper.ini";
}

/** Options \a P (GridParams, FlowParams, ...) with [section] of
 * config/paper.ini read over their defaults. */
template <class P>
P paperPreset(const std::string& section)
{
	mrpt::config::CConfigFile f(paperIni());
	P p;
	p.loadFromConfigFile(f, section);
	return p;
}
}  // namespace bims::test
