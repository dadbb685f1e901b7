// Running a built program from a test: its exit code and everything it
// printed (stdout and stderr).
#pragma once

#include <sys/wait.h>

#include <array>
#include <cstdio>
#include <string>

namespace bims::test
{
struct CommandResult
{
	int code = -1;    ///< exit code (-1: killed or could not start)
	std::string out;  ///< stdout and stderr
};

/** Runs \a command with the shell, stderr merged into stdout. */
inline CommandResult runCommand(const std::string& command)
{
	CommandResult r;
	FILE* p = popen((command + " 2>&1").c_str(), "r");
	if (!p) return r;
	std::array<char, 4096> buf;
	while (fgets(buf.data(), buf.size(), p)) r.out += buf.data();
	const int st = pclose(p);
	r.code = WIFEXITED(st) ? WEXITSTATUS(st) : -1;
	return r;
}
}  // namespace bims::test
