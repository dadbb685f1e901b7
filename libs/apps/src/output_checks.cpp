#include <bims/apps/app.h>
#include <bims/apps/output_checks.h>

#include <filesystem>
#include <set>
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
	// the outputs, the manifest aside (unless it is all there is)
	std::vector<std::string> outputs;
	for (const auto& f : found)
		if (fs::path(f).filename() != kOutputManifest) outputs.push_back(f);
	if (outputs.empty()) outputs = found;
	if (!overwrite)
		throw UsageError(
		    dir + ": holds the outputs of an earlier run (" +
		    std::to_string(outputs.size()) + " files, e.g. " +
		    fs::path(outputs.front()).lexically_relative(dir).string() +
		    "); give " + overwriteFlag +
		    " to replace them, or another output folder");
	// --overwrite: links at output names are replaced (never followed);
	// of the files, only those the earlier run's manifest lists go
	std::set<std::string> listed;
	try
	{
		for (const auto& f : manifestFiles(dir)) listed.insert(f);
	}
	catch (const std::runtime_error& e)
	{
		throw UsageError(e.what());
	}
	std::vector<std::string> links, kept;
	for (const auto& f : found)
	{
		const std::string rel = fs::path(f).lexically_relative(dir).string();
		if (std::error_code ec; fs::is_symlink(f, ec))
			links.push_back(f);
		else if (rel != kOutputManifest && !listed.count(rel))
		{
			// a partial file (of any run) of a listed file goes with it
			const fs::path r(rel);
			const std::string base = partialTarget(r.filename().string());
			if (base.empty() ||
			    !listed.count((r.parent_path() / base).string()))
				kept.push_back(rel);
		}
	}
	if (!kept.empty())
	{
		std::string names;
		for (size_t k = 0; k < kept.size() && k < 5; ++k)
			names += (k ? ", " : "") + kept[k];
		if (kept.size() > 5)
			names += " and " + std::to_string(kept.size() - 5) + " more";
		throw UsageError(
		    dir + ": " + overwriteFlag +
		    " removes only the files an earlier run's manifest (" +
		    kOutputManifest + ") lists; these are not in " +
		    (listed.empty() ? "one (there is none)" : "it") +
		    " and are kept: " + names +
		    "; remove them yourself, or give another output folder");
	}
	for (const auto& l : links)
		if (std::error_code ec; !fs::remove(l, ec) || ec)
			throw std::runtime_error(l + ": cannot remove the link for " +
			                         overwriteFlag + ": " + ec.message());
	return links.size() + removeListedOutputs(dir, overwriteFlag);
}

}  // namespace bims
