#include <bims/common/warnings.h>

#include <utility>

namespace bims
{
namespace
{
WarningCallback& programSlot()
{
	static WarningCallback cb;
	return cb;
}
}  // namespace

const WarningCallback& programWarnings()
{
	return programSlot();
}

void setProgramWarnings(WarningCallback cb)
{
	programSlot() = std::move(cb);
}

}  // namespace bims
