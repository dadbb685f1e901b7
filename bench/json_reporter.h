// A Google Benchmark reporter printing one JSON object per measurement on
// stdout, e.g. {"name":"tier0/all/bonn","voxel_m":0.02,"ms_median":1.9,...},
// so that runs can be compared by script. Counters of the benchmark become
// fields. With repetitions, only the median/mean/stddev aggregates are
// printed ("ms_median", "ms_mean", "ms_stddev" in one object) plus
// "cpu_ms_median" (process CPU time of the benchmark thread, the better
// figure when other jobs share the machine).
#pragma once

#include <benchmark/benchmark.h>

#include <map>
#include <string>

namespace bims::bench
{
/** The fields of each measurement printed, by benchmark name. */
using Results = std::map<std::string, std::map<std::string, double>>;

class JsonLinesReporter : public benchmark::BenchmarkReporter
{
 public:
	/** \param results if given, receives every measurement printed. */
	explicit JsonLinesReporter(Results* results = nullptr) : results_(results)
	{
	}
	bool ReportContext(const Context& context) override;
	void ReportRuns(const std::vector<Run>& runs) override;
	void Finalize() override;

 private:
	struct Acc
	{
		std::map<std::string, double> fields;
		std::string name;
	};
	Results* results_;
	std::map<std::string, Acc> pending_;
	std::vector<std::string> order_;
	void flush(const std::string& key);
};

/** Runs the registered benchmarks with JsonLinesReporter on stdout (and
 * Google Benchmark's console table on stderr); \a results, if given,
 * receives the measurements. */
int runWithJsonLines(int argc, char** argv, Results* results = nullptr);

/** The value of a "--key=value" argument: a pointer into \a arg after
 * "key=", or nullptr if \a arg is not that option. The benchmarks' own
 * options; the others go on to Google Benchmark. */
inline const char* flagValue(const char* arg, const char* key)
{
	const std::string a = arg, p = std::string(key) + "=";
	return a.rfind(p, 0) == 0 ? arg + p.size() : nullptr;
}

}  // namespace bims::bench
