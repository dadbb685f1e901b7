#include "json_reporter.h"

#include <bims/io/json.h>

#include <cmath>
#include <cstdio>
#include <iostream>
#include <sstream>

namespace bims::bench
{
bool JsonLinesReporter::ReportContext(const Context&)
{
	return true;
}

namespace
{
double toMs(const benchmark::BenchmarkReporter::Run& r, double t)
{
	switch (r.time_unit)
	{
		case benchmark::kNanosecond:
			return t * 1e-6;
		case benchmark::kMicrosecond:
			return t * 1e-3;
		case benchmark::kMillisecond:
			return t;
		case benchmark::kSecond:
			return t * 1e3;
	}
	return t;
}
}  // namespace

void JsonLinesReporter::ReportRuns(const std::vector<Run>& runs)
{
	for (const auto& r : runs)
	{
		if (r.error_occurred)
		{
			std::cout << jsonLine({{"name", r.benchmark_name()},
			                       {"error", r.error_message}})
			          << "\n";
			continue;
		}
		const std::string key = r.run_name.function_name;
		if (!pending_.count(key)) order_.push_back(key);
		auto& acc = pending_[key];
		acc.name = key;
		const double ms = toMs(r, r.GetAdjustedRealTime());
		const double cpu = toMs(r, r.GetAdjustedCPUTime());
		if (r.run_type == Run::RT_Aggregate)
		{
			if (r.aggregate_name == "median" || r.aggregate_name == "mean" ||
			    r.aggregate_name == "stddev")
				acc.fields["ms_" + r.aggregate_name] = ms;
			if (r.aggregate_name == "median") acc.fields["cpu_ms_median"] = cpu;
		}
		else
		{
			acc.fields["ms_median"] = ms;  // single run: its mean
			acc.fields["cpu_ms_median"] = cpu;
			acc.fields["iterations"] = double(r.iterations);
		}
		// Counters of the median aggregate (or of the single run).
		if (r.run_type != Run::RT_Aggregate || r.aggregate_name == "median")
			for (const auto& [cname, c] : r.counters)
				acc.fields[cname] = c.value;
		if (r.run_type != Run::RT_Aggregate && r.repetitions <= 1) flush(key);
	}
}

void JsonLinesReporter::flush(const std::string& key)
{
	auto it = pending_.find(key);
	if (it == pending_.end()) return;
	Json j;
	j["name"] = it->second.name;
	auto vox = it->second.fields.find("voxel_m");
	if (vox != it->second.fields.end()) j["voxel_m"] = jsonNumber(vox->second);
	for (const auto& [k, v] : it->second.fields)
		if (k != "voxel_m") j[k] = jsonNumber(v);
	std::cout << jsonLine(j) << std::endl;
	if (results_) (*results_)[it->second.name] = it->second.fields;
	pending_.erase(it);
}

void JsonLinesReporter::Finalize()
{
	for (const auto& k : order_) flush(k);
	order_.clear();
}

int runWithJsonLines(int argc, char** argv, Results* results)
{
	benchmark::Initialize(&argc, argv);
	if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
	JsonLinesReporter json(results);
	benchmark::RunSpecifiedBenchmarks(&json);
	benchmark::Shutdown();
	return 0;
}

}  // namespace bims::bench
