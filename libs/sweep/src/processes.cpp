#include <bims/io/output_paths.h>
#include <bims/sweep/processes.h>
#include <fcntl.h>
#include <sys/prctl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <csignal>
#include <cstring>
#include <stdexcept>
#include <thread>

namespace bims::sweep
{
namespace
{
using Clock = std::chrono::steady_clock;

struct Running
{
	size_t index;
	pid_t pid;
	Clock::time_point start;
};

/** Forks and executes \a job; its output into the (opened) log. */
pid_t launch(const Job& job)
{
	if (job.argv.empty()) throw std::invalid_argument("a job without argv");
	replaceSymlink(job.log);
	const int fd =
	    open(job.log.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
	if (fd < 0)
		throw std::runtime_error(job.log +
		                         ": cannot create: " + std::strerror(errno));
	std::vector<char*> args;
	for (const auto& a : job.argv) args.push_back(const_cast<char*>(a.c_str()));
	args.push_back(nullptr);
	const pid_t parent = getpid();
	const pid_t pid = fork();
	if (pid == 0)
	{
		// only async-signal-safe calls from here on
		setpgid(0, 0);
		prctl(PR_SET_PDEATHSIG, SIGTERM);
		if (getppid() != parent) _exit(128 + SIGTERM);  // parent gone
		const int in = open("/dev/null", O_RDONLY);
		if (in >= 0) dup2(in, 0);
		dup2(fd, 1);
		dup2(fd, 2);
		execv(args[0], args.data());
		const char* why = std::strerror(errno);
		const char msg[] = "bims-sweep: cannot execute ";
		[[maybe_unused]] ssize_t w = write(2, msg, sizeof(msg) - 1);
		w = write(2, args[0], std::strlen(args[0]));
		w = write(2, ": ", 2);
		w = write(2, why, std::strlen(why));
		w = write(2, "\n", 1);
		_exit(127);
	}
	const int forkErr = errno;
	close(fd);
	if (pid < 0)
		throw std::runtime_error("cannot start " + job.argv[0] + ": " +
		                         std::strerror(forkErr));
	return pid;
}
}  // namespace

std::vector<JobOutcome> runJobs(const std::vector<Job>& jobs,
                                const PoolOptions& opt)
{
	std::vector<JobOutcome> out(jobs.size());
	std::vector<Running> running;
	size_t next = 0;
	bool forwarded = false;
	std::string error;
	for (;;)
	{
		const bool stopping = opt.stop && opt.stop->load();
		if (stopping && !forwarded)
		{
			const int sig = opt.stopSignal ? opt.stopSignal() : 0;
			for (const auto& r : running) kill(r.pid, sig ? sig : SIGINT);
			forwarded = true;
		}
		while (!stopping && error.empty() && next < jobs.size() &&
		       running.size() < std::max<size_t>(opt.workers, 1))
		{
			try
			{
				const pid_t pid = launch(jobs[next]);
				out[next].started = true;
				running.push_back({next, pid, Clock::now()});
				next++;
			}
			catch (const std::exception& e)
			{
				error = e.what();
			}
		}
		if (running.empty()) break;
		bool reaped = false;
		for (size_t i = 0; i < running.size();)
		{
			int st = 0;
			const pid_t p = waitpid(running[i].pid, &st, WNOHANG);
			if (p == 0 || (p < 0 && errno == EINTR))
			{
				i++;
				continue;
			}
			JobOutcome& o = out[running[i].index];
			o.seconds =
			    std::chrono::duration<double>(Clock::now() - running[i].start)
			        .count();
			if (p > 0 && WIFSIGNALED(st))
			{
				o.signal = WTERMSIG(st);
				o.exitCode = 128 + o.signal;
			}
			else
				o.exitCode = p > 0 ? WEXITSTATUS(st) : 127;
			const size_t index = running[i].index;
			running.erase(running.begin() + static_cast<long>(i));
			reaped = true;
			if (opt.onDone) opt.onDone(index, o);
		}
		if (!reaped) std::this_thread::sleep_for(std::chrono::milliseconds(20));
	}
	if (!error.empty()) throw std::runtime_error(error);
	return out;
}

}  // namespace bims::sweep
