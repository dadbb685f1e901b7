// Shared entry-point plumbing for the bims command-line programs.
#pragma once

#include <functional>
#include <stdexcept>
#include <string>

namespace bims
{
/** Runs \a body, turning any exception into "PROGRAM: error: what" on stderr
 * and exit code 1 (2 for command-line usage errors). Libraries throw; only
 * main() decides to exit. */
int runApp(const std::string& program, const std::function<int()>& body);

/** Thrown for wrong command-line usage (exit code 2). */
struct UsageError : std::runtime_error
{
	using std::runtime_error::runtime_error;
};

/** Creates a directory and its parents; throws naming it on failure. */
void makeDirs(const std::string& path);

}  // namespace bims
