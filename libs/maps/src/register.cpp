#include <bims/maps/CMotionGridBase.h>
#include <bims/maps/register.h>

#include <mrpt/rtti/CObject.h>

#include <mutex>

namespace bims::maps
{
void registerClasses()
{
	static std::once_flag once;
	std::call_once(
	    once,
	    []
	    {
		    mrpt::rtti::registerClass(CLASS_ID(CBayesVoxelGridBase));
		    mrpt::rtti::registerClass(CLASS_ID(CMotionGridBase));
		    mrpt::rtti::registerClass(CLASS_ID(COccupancyBayesGrid));
		    mrpt::rtti::registerClass(CLASS_ID(CBackgroundSubtractionGrid));
		    mrpt::rtti::registerClass(CLASS_ID(CFlowConsistencyGrid));
	    });
}

namespace
{
// Runs at load time when this object file is linked (bims::maps links the
// library as a whole archive): the ini loader and ReadObject() then know
// the grids even if the program never names one of them.
struct AutoRegister
{
	AutoRegister() { registerClasses(); }
} autoRegister;
}  // namespace

}  // namespace bims::maps
