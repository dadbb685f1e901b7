#include <bims/apps/app.h>
#include <bims/apps/input_kind.h>

#include <cctype>
#include <filesystem>
#include <fstream>
#include <sstream>

namespace bims::apps
{
namespace fs = std::filesystem;

InputKind inputKind(const std::string& path)
{
	std::error_code ec;
	const auto st = fs::status(path, ec);
	if (!fs::exists(st)) return InputKind::Missing;
	if (fs::is_directory(st))
	{
		const auto has = [&](const char* f)
		{ return fs::exists(fs::path(path) / f, ec); };
		if (has("rgb.txt") || has("depth.txt")) return InputKind::TumFolder;
		if (has("odometry.csv")) return InputKind::StrayFolder;
		return InputKind::Folder;
	}
	if (!fs::is_regular_file(st)) return InputKind::Other;
	std::ifstream in(path, std::ios::binary);
	if (!in) return InputKind::Other;
	std::string head(4096, '\0');
	in.read(head.data(), static_cast<std::streamsize>(head.size()));
	head.resize(static_cast<size_t>(in.gcount()));
	if (head.empty()) return InputKind::Other;  // left to the reader
	for (unsigned char c : head)
		if (c == 0 || (c < 0x20 && c != '\n' && c != '\r' && c != '\t'))
			return InputKind::Binary;
	std::istringstream lines(head);
	std::string line;
	while (std::getline(lines, line))
	{
		size_t a = 0;
		while (a < line.size() &&
		       std::isspace(static_cast<unsigned char>(line[a])))
			a++;
		if (a < line.size() && line[a] == '[' &&
		    line.find(']', a) != std::string::npos)
			return InputKind::IniText;
	}
	return InputKind::OtherText;
}

namespace
{
/** Whether the .ini at \a path is a simulator scene (it has [sim]), not
 * an experiment. */
bool isSceneIni(const std::string& path)
{
	std::ifstream in(path);
	for (std::string line; std::getline(in, line);)
	{
		const size_t a = line.find_first_not_of(" \t");
		if (a != std::string::npos && line.compare(a, 5, "[sim]") == 0)
			return true;
	}
	return false;
}

std::string folderKindName(InputKind k)
{
	return k == InputKind::TumFolder ? "a TUM RGB-D folder"
	                                 : "a Stray Scanner capture";
}
}  // namespace

std::string importCommandFor(InputKind kind, const std::string& folder)
{
	if (kind == InputKind::TumFolder)
		return "bims-import-tum " + folder + " -o OUT.rawlog -c CONFIG.ini";
	if (kind == InputKind::StrayFolder)
		return "bims-import-stray " + folder + " -o OUT.rawlog -c stray.ini";
	return "";
}

void checkRawlogInputKind(const std::string& r, const std::string& usage)
{
	const InputKind k = inputKind(r);
	if (k == InputKind::IniText)
		throw UsageError(
		    r + ": an .ini where a rawlog belongs: " + usage +
		    (isSceneIni(r) ? " (a simulator scene makes a rawlog: bims-sim " +
		                         r + " -o OUT.rawlog)"
		                   : " (an experiment .ini: it goes with a rawlog, "
		                     "e.g. bims-run " +
		                         r + " IN.rawlog -o OUTDIR)"));
	if (k == InputKind::TumFolder || k == InputKind::StrayFolder)
		throw UsageError(r + ": " + folderKindName(k) +
		                 ", not a rawlog; import it first: " +
		                 importCommandFor(k, r) + ", then " + usage);
	if (k == InputKind::Folder)
		throw UsageError(r + ": a folder, not a rawlog file: " + usage);
	if (k == InputKind::OtherText)
		throw UsageError(
		    r + ": a text file, not a rawlog (rawlogs are binary): " + usage);
}

void checkRunInputKinds(const std::string& config,
                        const std::vector<std::string>& rawlogs)
{
	const std::string usage =
	    "bims-run CONFIG.ini IN.rawlog [MORE.rawlog...] -o OUTDIR";
	const InputKind ck = inputKind(config);
	std::vector<InputKind> rk;
	for (const auto& r : rawlogs) rk.push_back(inputKind(r));
	// swapped: a binary file first, an .ini among the rawlogs
	for (size_t i = 0; i < rawlogs.size(); i++)
		if (ck == InputKind::Binary && rk[i] == InputKind::IniText)
			throw UsageError("the arguments are swapped: " + config +
			                 " is a rawlog and " + rawlogs[i] +
			                 " an .ini; the experiment .ini comes first: "
			                 "bims-run " +
			                 rawlogs[i] + " " + config + " -o OUTDIR");
	if (ck == InputKind::Binary)
		throw UsageError(config +
		                 ": a binary file (a rawlog?) where the experiment "
		                 ".ini belongs: " +
		                 usage +
		                 " (a preset by name: bims-run default.ini "
		                 "IN.rawlog -o OUTDIR)");
	if (ck == InputKind::TumFolder || ck == InputKind::StrayFolder)
		throw UsageError(config + ": " + folderKindName(ck) +
		                 " where the experiment .ini belongs; import it into "
		                 "a rawlog first: " +
		                 importCommandFor(ck, config) + ", then " + usage);
	if (ck == InputKind::Folder)
		throw UsageError(
		    config + ": a folder where the experiment .ini belongs: " + usage);
	for (const auto& r : rawlogs) checkRawlogInputKind(r, usage);
}

}  // namespace bims::apps
