#include <bims/common/version.h>

namespace bims
{
const char* version()
{
	return BIMS_VERSION;
}

}  // namespace bims
