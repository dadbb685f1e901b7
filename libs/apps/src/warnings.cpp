#include <bims/apps/warnings.h>

#include <cstdio>

namespace bims
{
std::string wordWarning(const std::string& program, const Warning& w)
{
	std::string line = program + ": ";
	if (w.kind == Warning::Kind::Warning)
		line += "warning: ";
	else if (w.kind == Warning::Kind::Note)
		line += "note: ";
	if (!w.where.empty()) line += w.where + ": ";
	return line + w.text + "\n";
}

WarningCallback stderrWarnings(const std::string& program)
{
	return [program](const Warning& w)
	{ std::fputs(wordWarning(program, w).c_str(), stderr); };
}

}  // namespace bims
