#include <bims/apps/app.h>
#include <bims/apps/import_options.h>
#include <bims/common/config.h>

#include <filesystem>
#include <stdexcept>

namespace bims::apps
{
void checkGzLevel(int gz)
{
	if (gz < 0 || gz > 9) throw UsageError("--gz must be in 0..9");
}

std::unique_ptr<mrpt::config::CConfigFile> openImportConfig(
    const std::optional<std::string>& config)
{
	if (!config) return nullptr;
	if (!std::filesystem::exists(*config))
		throw std::runtime_error(*config + ": config file not found");
	return openIniFile(*config);
}
}  // namespace bims::apps
