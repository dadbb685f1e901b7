// The body the bag fuzz targets share (fuzz_bag, fuzz_mcap, fuzz_db3): the
// input written to a file of the scratch folder (the readers map files), its
// topics listed as --topics lists them (optional), then imported into a plain
// rawlog; a clear error is the expected answer to a bad file, a crash or a
// sanitizer report is a finding.
#pragma once

#include <bims/bag/bag_import.h>

#include <exception>
#include <filesystem>
#include <string>

#include "fuzz_common.h"

namespace bims::fuzz
{
inline void importBagInput(const std::string& fileName, const uint8_t* data,
                           size_t size, bool listTopics)
{
	const std::string bag = writeFile(fileName, data, size);
	const std::string out = scratchDir() + "/out.rawlog";
	if (listTopics)
	{
		try
		{
			(void)bims::bag::bagTopics({bag});
		}
		catch (const std::exception&)
		{
		}
	}
	try
	{
		bims::bag::BagImportOptions o;
		o.gzLevel = 0;
		(void)bims::bag::importBag({bag}, out, bims::bag::BagImportParams{}, o);
	}
	catch (const std::exception&)
	{
	}
	std::error_code ec;
	std::filesystem::remove(out, ec);
	std::filesystem::remove(out + ".partial", ec);
}
}  // namespace bims::fuzz
