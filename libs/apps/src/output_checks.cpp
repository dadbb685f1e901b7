#include <bims/apps/app.h>
#include <bims/apps/output_checks.h>

#include <filesystem>
#include <stdexcept>

namespace fs = std::filesystem;

namespace bims
{
namespace
{
/** The path with links, `.` and `..` resolved as far as it exists. */
fs::path resolved(const std::string& p)
{
	std::error_code ec;
	fs::path r = fs::weakly_canonical(p, ec);
	if (ec) r = fs::absolute(p, ec).lexically_normal();
	return r;
}

/** \a inner is \a outer or lies inside it (component by component). */
bool within(const fs::path& inner, const fs::path& outer)
{
	auto i = inner.begin();
	for (auto o = outer.begin(); o != outer.end(); ++o, ++i)
	{
		if (o->empty() && std::next(o) == outer.end()) break;  // trailing '/'
		if (i == inner.end() || *i != *o) return false;
	}
	return true;
}
}  // namespace

void checkOutputsSpareInputs(const std::vector<std::string>& inputs,
                             const std::vector<std::string>& outputs)
{
	std::vector<fs::path> resolvedIn;  // once: a folder may hold thousands
	for (const auto& in : inputs)
		resolvedIn.push_back(in.empty() ? fs::path() : resolved(in));
	for (const auto& out : outputs)
	{
		if (out.empty())
			throw UsageError(
			    "the output path is empty (nothing would be "
			    "written)");
		const fs::path ro = resolved(out);
		for (size_t k = 0; k < inputs.size(); ++k)
		{
			const auto& in = inputs[k];
			if (in.empty()) continue;
			const fs::path& ri = resolvedIn[k];
			if (!within(ri, ro)) continue;
			const std::string both =
			    ro == fs::path(out) && ri == fs::path(in)
			        ? std::string()
			        : " (" + ro.string() + " and " + ri.string() + ")";
			if (ri == ro)
				throw UsageError("output " + out +
				                 " would overwrite the input " + in + both);
			throw UsageError("output folder " + out + " contains the input " +
			                 in + both +
			                 ": choose an output that holds no input");
		}
	}
}

size_t prepareOutputFolder(const std::string& dir,
                           const OutputFolderLayout& layout, bool overwrite,
                           const std::string& overwriteFlag)
{
	const auto found = earlierOutputs(dir, layout);
	if (found.empty()) return 0;
	if (!overwrite)
		for (const auto& f : found)
			if (std::error_code ec; fs::is_symlink(f, ec))
				throw UsageError(
				    f +
				    ": a symbolic link where the run writes a folder of its "
				    "own: remove it, or give " +
				    overwriteFlag +
				    " to replace the link (what it points to is never "
				    "touched)");
	if (!overwrite)
		throw UsageError(
		    dir + ": holds the outputs of an earlier run (" +
		    std::to_string(found.size()) + " files, e.g. " +
		    fs::path(found.front()).lexically_relative(dir).string() +
		    "); give " + overwriteFlag +
		    " to replace them, or another output folder");
	return removeEarlierOutputs(dir, layout, overwriteFlag);
}

}  // namespace bims
