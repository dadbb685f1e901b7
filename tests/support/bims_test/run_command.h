// Running a built program from a test: its exit code and everything it
// printed (stdout and stderr).
#pragma once

#include <fcntl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

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
/** Starts \a argv (argv[0] is the program's path) with stdout and stderr in
 * \a log, sends it \a sig once \a file exists (or after 8 s), and waits for
 * it. Returns its exit code, or -signal if the signal killed it. */
inline int signalWhenExists(const std::vector<std::string>& argv,
                            const std::string& log, const std::string& file,
                            int sig)
{
	std::vector<char*> args;
	for (const auto& a : argv) args.push_back(const_cast<char*>(a.c_str()));
	args.push_back(nullptr);
	const pid_t pid = fork();
	if (pid == 0)
	{
		const int fd = open(log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
		dup2(fd, 1);
		dup2(fd, 2);
		execv(args[0], args.data());
		_exit(127);
	}
	for (int i = 0; i < 4000 && !std::filesystem::exists(file); i++)
		usleep(2000);
	kill(pid, sig);
	int st = 0;
	waitpid(pid, &st, 0);
	return WIFEXITED(st) ? WEXITSTATUS(st) : -WTERMSIG(st);
}
}  // namespace bims::test
