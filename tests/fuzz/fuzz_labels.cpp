// Fuzz target: what bims-eval masks reads. The first byte chooses: 0 a
// label image (PNG, read as loadMask does, then the masks_proxy convention
// 255 / 0 / ignored 150, 50), 1 a run's frames.csv (readFrameStamps), 2 a
// list of label values (parseLabelValues).
#include <bims/eval/mask_labels.h>
#include <bims/eval/mask_metrics.h>

#include <exception>

#include "fuzz_common.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size)
{
	using namespace bims::eval;
	if (size == 0) return 0;
	const uint8_t mode = data[0] % 3;
	++data;
	--size;
	try
	{
		if (mode == 0)
		{
			const cv::Mat labels =
			    loadMask(bims::fuzz::writeFile("label.png", data, size));
			cv::Mat moving, scored;
			LabelConvention::explicitValues(255, 0, {150, 50})
			    .toContract(labels, moving, scored);
		}
		else if (mode == 1)
			(void)readFrameStamps(
			    bims::fuzz::writeFile("frames.csv", data, size));
		else
			(void)parseLabelValues(
			    std::string(reinterpret_cast<const char*>(data), size));
	}
	catch (const std::exception&)
	{
	}
	return 0;
}
