// A full disk for a test: a child process whose files may not grow beyond a
// size.
#pragma once

#include <csignal>
#include <functional>

#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

namespace bims::test
{
/** Runs \a body in a forked child whose files may not grow beyond \a bytes
 * (SIGXFSZ ignored: a write beyond fails with EFBIG, as on a full disk).
 * Returns body's result as the child's exit status, or -1 when the child
 * did not exit normally (or could not be forked). */
inline int exitOfChildWithFileSizeLimit(rlim_t bytes,
                                        const std::function<int()>& body)
{
	const pid_t pid = fork();
	if (pid < 0) return -1;
	if (pid == 0)
	{
		std::signal(SIGXFSZ, SIG_IGN);
		const rlimit lim{bytes, bytes};
		setrlimit(RLIMIT_FSIZE, &lim);
		int code = 99;
		try
		{
			code = body();
		}
		catch (...)
		{
		}
		_exit(code);
	}
	int status = 0;
	waitpid(pid, &status, 0);
	return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}
}  // namespace bims::test
