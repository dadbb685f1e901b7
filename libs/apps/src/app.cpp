#include <bims/apps/app.h>
#include <bims/apps/warnings.h>
#include <bims/common/errors.h>
#include <mrpt/3rdparty/tclap/CmdLine.h>

#include <algorithm>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#if defined(__GLIBC__)
#include <malloc.h>
#endif
#include <sstream>
#include <stdexcept>

namespace bims
{
void keepFreedMemoryForReuse()
{
#if defined(__GLIBC__)
	// Blocks up to 32 MB (glibc's largest threshold) from the heap instead
	// of a mapping of their own, and the heap's free top kept up to 1 GB:
	// with the defaults, buffers of a few MB freed on one thread and
	// allocated again on another went back to the system and came back as
	// zeroed pages (two thirds of the page faults of a bims-run).
	mallopt(M_MMAP_THRESHOLD, 32 * 1024 * 1024);
	mallopt(M_TRIM_THRESHOLD, 1024 * 1024 * 1024);
#endif
}

namespace
{
/** Edit distance (insertions, deletions, substitutions) of two words. */
size_t editDistance(const std::string& a, const std::string& b)
{
	std::vector<size_t> row(b.size() + 1);
	for (size_t j = 0; j <= b.size(); ++j) row[j] = j;
	for (size_t i = 1; i <= a.size(); ++i)
	{
		size_t diag = row[0];
		row[0] = i;
		for (size_t j = 1; j <= b.size(); ++j)
		{
			const size_t up = row[j];
			row[j] = std::min({row[j] + 1, row[j - 1] + 1,
			                   diag + (a[i - 1] == b[j - 1] ? 0 : 1)});
			diag = up;
		}
	}
	return row[b.size()];
}

bool isNumber(const std::string& s)
{
	char* end = nullptr;
	std::strtod(s.c_str(), &end);
	return end && *end == '\0';
}
}  // namespace

void checkOptionNames(int argc, char** argv,
                      const std::vector<OptionName>& known)
{
	const auto find = [&](const std::string& n) -> const OptionName*
	{
		for (const auto& k : known)
			if (k.name == n) return &k;
		return nullptr;
	};
	for (int i = 1; i < argc; ++i)
	{
		const std::string word = argv[i];
		if (word == "--") return;  // the rest is positional
		if (word.size() < 2 || word[0] != '-' || isNumber(word)) continue;
		const std::string name = word.substr(0, word.find('='));
		if (const auto* k = find(name))
		{
			if (name.size() != word.size())  // TCLAP takes no "--x=v"
				throw UsageError(
				    "'" + word + "': give the value after a space (" + name +
				    " " + word.substr(name.size() + 1) + "); see --help");
			if (k->takesValue) ++i;  // its value
			continue;
		}
		if (word[1] != '-')  // combined short switches, "-qv"
		{
			bool all = true;
			for (size_t c = 1; c < word.size() && all; ++c)
			{
				const auto* k = find(std::string("-") + word[c]);
				all = k && !k->takesValue;
			}
			if (all) continue;
		}
		std::string msg = "unknown option '" + name + "'";
		const OptionName* best = nullptr;
		size_t bestD = 3;  // suggest within two edits
		for (const auto& k : known)
		{
			const size_t d = editDistance(name, k.name);
			if (k.name.size() > 2 && d < bestD) best = &k, bestD = d;
		}
		if (best) msg += " (did you mean " + best->name + "?)";
		throw UsageError(msg + "; see --help");
	}
}

std::vector<std::string> renameOptions(int argc, char** argv,
                                       const std::vector<OptionRename>& renamed,
                                       const std::vector<OptionName>& known)
{
	std::vector<std::string> args(argv, argv + argc);
	const std::string program =
	    argc > 0 ? std::filesystem::path(argv[0]).filename().string() : "";
	const auto takesValue = [&](const std::string& name)
	{
		for (const auto& k : known)
			if (k.name == name) return k.takesValue;
		return false;
	};
	for (size_t i = 1; i < args.size(); ++i)
	{
		if (args[i] == "--") break;  // the rest is positional
		for (const auto& r : renamed)
		{
			if (args[i] != r.old) continue;
			args[i] = r.now;
			const std::string value = takesValue(r.now) && i + 1 < args.size()
			                              ? " " + args[i + 1]
			                              : "";
			std::fprintf(stderr, "%s: note: %s%s is now %s%s\n",
			             program.c_str(), r.old.c_str(), value.c_str(),
			             r.now.c_str(), value.c_str());
			break;
		}
		if (takesValue(args[i])) ++i;  // its value is no option
	}
	return args;
}

int runApp(const std::string& program, const std::function<int()>& body)
{
	// the libraries' warnings, worded as this program's
	setProgramWarnings(stderrWarnings(program));
	try
	{
		return body();
	}
	catch (const ExitRequest& e)
	{
		return e.code;
	}
	catch (const TCLAP::ArgException& e)
	{
		std::fprintf(stderr, "%s: usage error: %s (%s)\n", program.c_str(),
		             e.error().c_str(), e.argId().c_str());
		return 2;
	}
	catch (const UsageError& e)
	{
		std::fprintf(stderr, "%s: usage error: %s\n", program.c_str(),
		             e.what());
		return 2;
	}
	catch (const std::exception& e)
	{
		std::fprintf(stderr, "%s: error: %s\n", program.c_str(),
		             withoutBacktrace(e.what()).c_str());
		return 1;
	}
}

namespace
{
std::atomic<bool> gStop{false};
std::atomic<int> gStopSignal{0};

extern "C" void onStopSignal(int sig)
{
	gStopSignal = sig;
	gStop = true;
	// a second signal kills at once (default action)
	std::signal(SIGINT, SIG_DFL);
	std::signal(SIGTERM, SIG_DFL);
}
}  // namespace

const std::atomic<bool>& installStopSignals()
{
	std::signal(SIGINT, onStopSignal);
	std::signal(SIGTERM, onStopSignal);
	return gStop;
}

int stopSignal()
{
	return gStopSignal;
}

std::set<size_t> parseIndexList(const std::string& text,
                                const std::string& flag)
{
	std::set<size_t> out;
	std::stringstream ss(text);
	std::string tok;
	while (std::getline(ss, tok, ','))
	{
		size_t used = 0;
		unsigned long v = 0;
		try
		{
			v = std::stoul(tok, &used);
		}
		catch (const std::exception&)
		{
			used = 0;
		}
		if (used == 0 || used != tok.size() || tok[0] == '-')
			throw UsageError(flag + ": bad index '" + tok + "'");
		out.insert(static_cast<size_t>(v));
	}
	return out;
}

void printMissingArguments(const std::string& argv0, const std::string& list)
{
	const auto slash = argv0.rfind('/');
	const std::string program =
	    slash == std::string::npos ? argv0 : argv0.substr(slash + 1);
	std::fprintf(stderr, "%s: usage error: missing %s; see --help\n",
	             program.c_str(), list.c_str());
}

}  // namespace bims
