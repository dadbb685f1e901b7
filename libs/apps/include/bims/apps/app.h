// The app base of every bims program (MRPT's mrpt::apps pattern). A
// program's main declares its command line (TCLAP) and hands the rest to
// runApp:
//   parse   parseCommandLine: --help and --version, unknown or mistyped
//           options, the old spellings still taken (docs/cli.md);
//   check   the run's own checks of its options (inRange, the output
//           checks of output_checks.h): a UsageError, before any work;
//   run     the program's run, one function of libs/apps;
//   report  an error on stderr as "PROGRAM: error: WHAT" (or "usage
//           error"), never a call stack;
//   exit    0 done, 1 error, 2 usage (ExitRequest: a code of its own).
// The libraries below throw plain errors (std::runtime_error,
// std::invalid_argument, bims::ConfigError) and report progress through a
// callback; only this layer speaks of usage.
#pragma once

#include <bims/common/version.h>

#include <atomic>
#include <functional>
#include <optional>
#include <set>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

namespace bims
{
/** Runs \a body (parse, check, run: its return value is the exit code),
 * turning any exception into "PROGRAM: error: what" on stderr and exit code
 * 1 (2 for command-line usage errors). Libraries throw; only main()
 * decides to exit. An MRPT exception's text is cut to its message
 * (bims::withoutBacktrace, bims/common/errors.h). */
int runApp(const std::string& program, const std::function<int()>& body);

/** Thrown for wrong command-line usage (exit code 2). */
struct UsageError : std::runtime_error
{
	using std::runtime_error::runtime_error;
};

/** Thrown to end a program early with this exit code and no further
 * message (runApp returns it), e.g. after --help. */
struct ExitRequest
{
	int code = 0;
};

/** One option a program declares: "--frames" or "-o", and whether a value
 * follows it. */
struct OptionName
{
	std::string name;
	bool takesValue = false;
};

/** Throws UsageError for the first word of \a argv that looks like an
 * option ("-x", "--xyz", "--xyz=v"; not a number, not after "--") but is
 * none of \a known, naming it and the closest known one ("did you mean"),
 * or a known one written "--x=v" (TCLAP would take the word as an input).
 * Combined short switches ("-qv") pass when each letter is known. TCLAP
 * alone takes an unknown "--frmes" as an input file when the program
 * accepts several. */
void checkOptionNames(int argc, char** argv,
                      const std::vector<OptionName>& known);

/** An option renamed by the shared command-line vocabulary (docs/cli.md):
 * the old spelling still works, with a one-line note on stderr. */
struct OptionRename
{
	std::string old;  ///< e.g. "--frames" (a count in bims-sim)
	std::string now;  ///< e.g. "--max-frames"
};

/** \a argv (all \a argc words) with the \a renamed options written their
 * new way; for each
 * one met, prints "PROGRAM: note: OLD V is now NEW V" on stderr (PROGRAM:
 * \a argv[0]'s file name). \a known: the program's options (whether NEW
 * takes a value). Words after "--" stay as they are. */
std::vector<std::string> renameOptions(int argc, char** argv,
                                       const std::vector<OptionRename>& renamed,
                                       const std::vector<OptionName>& known);

/** The options a TCLAP command line declares ("-o" and "--out" of each). */
template <class CmdLine>
std::vector<OptionName> declaredOptions(CmdLine& cmd)
{
	std::vector<OptionName> known;
	for (const auto* a : cmd.getArgList())
	{
		// positional arguments print as "<NAME>", options as "-f <N>"
		// ("[-f <N>]" when optional)
		const std::string id = a->shortID();
		if (id.rfind("-", 0) != 0 && id.rfind("[-", 0) != 0) continue;
		if (!a->getFlag().empty())
			known.push_back({"-" + a->getFlag(), a->isValueRequired()});
		if (!a->getName().empty())
			known.push_back({"--" + a->getName(), a->isValueRequired()});
	}
	return known;
}

/** "PROGRAM: usage error: missing LIST; see --help" on stderr (\a argv0:
 * the program's path). */
void printMissingArguments(const std::string& argv0, const std::string& list);

/** Parses the command line with MRPT's TCLAP (CmdLine in
 * mrpt/3rdparty/tclap/CmdLine.h), which prints --help, --version and parse
 * errors itself and then returns false instead of exiting: throws
 * ExitRequest{0} after --help or --version, ExitRequest{2} after a parse
 * error, so that no program goes on with empty arguments. An unknown or
 * mistyped option is a UsageError before anything else (checkOptionNames).
 * \a renamed: old spellings still taken (renameOptions). */
template <class CmdLine>
void parseCommandLine(CmdLine& cmd, int argc, char** argv,
                      const std::vector<OptionRename>& renamed = {})
{
	const std::vector<OptionName> known = declaredOptions(cmd);
	std::vector<std::string> args = renameOptions(argc, argv, renamed, known);
	std::vector<char*> words;
	for (auto& a : args) words.push_back(a.data());
	words.push_back(nullptr);
	const int n = static_cast<int>(args.size());
	bool help = false;
	for (const auto& a : args)
		help |= a == "-h" || a == "--help" || a == "--version";
	if (!help) checkOptionNames(n, words.data(), known);
	if (cmd.parse(n, words.data())) return;
	if (!help)
	{
		// TCLAP says only "one or more required arguments missing": name them
		std::string missing;
		for (const auto* a : cmd.getArgList())
			if (a->isRequired() && !a->isSet())
				missing += (missing.empty() ? "" : ", ") + a->shortID();
		if (!missing.empty())
			printMissingArguments(args.empty() ? "" : args[0], missing);
	}
	throw ExitRequest{help ? 0 : 2};
}

/** The values of those TCLAP value arguments that the command line gave
 * (e.g. the optional outputs, for checkOutputsSpareInputs). */
template <class... Arg>
std::vector<std::string> givenValues(Arg&... args)
{
	std::vector<std::string> v;
	(..., (args.isSet() ? v.push_back(args.getValue()) : void()));
	return v;
}

/** The value of a TCLAP value argument if the command line gave it (an
 * option's "given or not" for a library's options struct). */
template <class Arg>
auto givenValue(Arg& arg)
    -> std::optional<std::decay_t<decltype(arg.getValue())>>
{
	if (!arg.isSet()) return std::nullopt;
	return arg.getValue();
}

/** The value of a numeric TCLAP option, checked to lie in [\a lo, \a hi]
 * (NaN never does): a UsageError "--NAME V: out of range [lo, hi]" (with
 * \a hint when given) otherwise. Each program states each option's range
 * where it reads it. */
template <class Arg, class T>
auto inRange(Arg& arg, T lo, T hi, const std::string& hint = "")
    -> std::decay_t<decltype(arg.getValue())>
{
	const auto v = arg.getValue();
	if (!(v >= lo && v <= hi))
	{
		std::ostringstream s;
		s << "--" << arg.getName() << " " << v << ": out of range [" << lo
		  << ", " << hi << "]" << (hint.empty() ? "" : " (" + hint + ")");
		throw UsageError(s.str());
	}
	return v;
}

/** From now on SIGINT and SIGTERM ask the program to stop cleanly: the
 * returned flag turns true (the program finishes its current step, writes
 * what it has and exits); a second signal kills at once (default action).
 * For main() only: libraries take the flag. */
const std::atomic<bool>& installStopSignals();
/** The signal that set the stop flag (0: none yet). */
int stopSignal();

/** Tells the C library's allocator to keep freed memory for reuse instead
 * of returning it to the system at once: per-frame image buffers (several
 * MB at 640x480) then cost no page faults each frame (~5 ms of CPU per VGA
 * frame in bims-run; docs/journal/pipeline.md). For programs that process
 * frames in a loop; call once at the start of main(). */
void keepFreedMemoryForReuse();

/** "3,40,7" -> {3, 7, 40} (frame indices of a command-line flag); throws
 * UsageError naming \a flag and the bad item. */
std::set<size_t> parseIndexList(const std::string& text,
                                const std::string& flag);

}  // namespace bims
