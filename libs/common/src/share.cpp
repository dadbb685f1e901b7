#include <bims/common/share.h>

#include <filesystem>
#include <system_error>

// Set by libs/common/CMakeLists.txt from GNUInstallDirs.
#ifndef BIMS_SHARE_FROM_BIN
#error "BIMS_SHARE_FROM_BIN (share/bims relative to bin) must be defined"
#endif
#ifndef BIMS_INSTALL_SHARE_DIR
#error "BIMS_INSTALL_SHARE_DIR (the installed share/bims) must be defined"
#endif

namespace fs = std::filesystem;

namespace bims
{
namespace
{
/** dir/name, lexically normalised, if it is a regular file (or a link to
 * one); "" otherwise. */
std::string fileIn(const fs::path& dir, const std::string& name)
{
	if (dir.empty() || name.empty()) return {};
	const fs::path p = (dir / name).lexically_normal();
	std::error_code ec;
	return fs::is_regular_file(p, ec) ? p.string() : std::string();
}
}  // namespace

std::string executableDir()
{
	std::error_code ec;
	const fs::path exe = fs::canonical("/proc/self/exe", ec);
	return ec ? std::string() : exe.parent_path().string();
}

std::string installedShareDir()
{
	return BIMS_INSTALL_SHARE_DIR;
}

std::string findShareFile(const std::string& name, const std::string& exeDir)
{
	if (!exeDir.empty())
		if (auto p = fileIn(fs::path(exeDir) / BIMS_SHARE_FROM_BIN, name);
		    !p.empty())
			return p;
	return fileIn(installedShareDir(), name);
}

std::string findShareFile(const std::string& name)
{
	return findShareFile(name, executableDir());
}

std::string resolvePreset(const std::string& path)
{
	std::error_code ec;
	if (path.empty() || fs::exists(path, ec) || fs::path(path).is_absolute())
		return path;
	const std::string preset = findShareFile(path);
	return preset.empty() ? path : preset;
}

std::string presetHint(const std::string& path)
{
	if (path.empty() || fs::path(path).is_absolute()) return "";
	const std::string exe = executableDir();
	const std::string own =
	    exe.empty()
	        ? std::string()
	        : (fs::path(exe) / BIMS_SHARE_FROM_BIN).lexically_normal().string();
	return " (nor a preset of that name in " +
	       (own.empty() ? installedShareDir()
	                    : own + " or " + installedShareDir()) +
	       ")";
}

std::string defaultExperimentIni()
{
	return findShareFile("default.ini");
}

std::string parametersSource(const std::string& iniPath)
{
	return "parameters from " +
	       (iniPath.empty()
	            ? std::string(
	                  "built-in defaults (no share/bims/default.ini found)")
	            : iniPath);
}
}  // namespace bims
