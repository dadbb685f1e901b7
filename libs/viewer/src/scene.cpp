// The 3D view: registered cloud, the three tiers, trajectories.
#include <bims/common/frames.h>
#include <bims/viewer/controller.h>

#include <mrpt/maps/CColouredPointsMap.h>
#include <mrpt/obs/T3DPointsProjectionParams.h>
#include <mrpt/opengl/CFBORender.h>
#include <mrpt/opengl/CGridPlaneXY.h>
#include <mrpt/opengl/COctoMapVoxels.h>
#include <mrpt/opengl/CPointCloudColoured.h>
#include <mrpt/opengl/CSetOfLines.h>
#include <mrpt/opengl/CSetOfObjects.h>
#include <mrpt/opengl/stock_objects.h>

namespace bims::viewer
{
namespace
{
/** Voxels as cubes of side \a side [m], one colour. Moving voxels are drawn
 * larger than the tier-0 ones so that they show through the blue cubes
 * they sit in. */
mrpt::opengl::COctoMapVoxels::Ptr voxelCubes(
    const std::vector<mrpt::math::TPoint3D>& centres, double side,
    const mrpt::img::TColor& colour, const std::string& name)
{
	auto vox = mrpt::opengl::COctoMapVoxels::Create();
	vox->setName(name);
	vox->resizeVoxelSets(1);
	vox->reserveVoxels(0, centres.size());
	mrpt::math::TPoint3D lo(1e9, 1e9, 1e9), hi(-1e9, -1e9, -1e9);
	for (const auto& c : centres)
	{
		vox->push_back_Voxel(
		    0, mrpt::opengl::COctoMapVoxels::TVoxel(c, side, colour));
		lo.x = std::min(lo.x, c.x), lo.y = std::min(lo.y, c.y),
		lo.z = std::min(lo.z, c.z);
		hi.x = std::max(hi.x, c.x), hi.y = std::max(hi.y, c.y),
		hi.z = std::max(hi.z, c.z);
	}
	if (!centres.empty()) vox->setBoundingBox(lo, hi);
	vox->setVisualizationMode(mrpt::opengl::COctoMapVoxels::FIXED);
	vox->showGridLines(false);
	return vox;
}

mrpt::opengl::CSetOfLines::Ptr polyline(const Trajectory& traj,
                                        const mrpt::poses::CPose3D& align,
                                        const mrpt::img::TColor& c,
                                        const std::string& name)
{
	auto l = mrpt::opengl::CSetOfLines::Create();
	l->setName(name);
	l->setColor_u8(c);
	l->setLineWidth(2.5f);
	for (size_t i = 1; i < traj.size(); ++i)
	{
		const auto a = (align + traj[i - 1].T_WC).translation();
		const auto b = (align + traj[i].T_WC).translation();
		l->appendLine(a.x, a.y, a.z, b.x, b.y, b.z);
	}
	return l;
}
}  // namespace

void ReplayController::fillScene(mrpt::opengl::COpenGLScene& scene) const
{
	using namespace mrpt::opengl;
	scene.clear();
	auto vp = scene.getViewport();
	vp->setCustomBackgroundColor(mrpt::img::TColorf(0.12f, 0.12f, 0.14f));

	auto grid = CGridPlaneXY::Create(-5, 5, -5, 5, 0, 0.5);
	grid->setColor_u8(mrpt::img::TColor(90, 90, 90));
	scene.insert(grid);
	scene.insert(stock_objects::CornerXYZSimple(0.3f, 2.0f));

	const mrpt::poses::CPose3D T_WC = currentPose();

	if (layers_.cloud && frame_)
	{
		mrpt::maps::CColouredPointsMap pts;
		mrpt::obs::T3DPointsProjectionParams pp;
		auto& scan = *frame_->scan;
		const int d = opt_.cloudDecimation;
		pp.decimation =
		    (scan.rangeImage.cols() % d == 0 && scan.rangeImage.rows() % d == 0)
		        ? d
		        : 1;
		scan.unprojectInto(pts, pp);  // {S}, sensorPose not applied
		auto cloud = CPointCloudColoured::Create();
		cloud->setName("cloud");
		cloud->loadFromPointsMap(&pts);
		cloud->setPointSize(2.0f);
		cloud->setPose(T_WC + (mrpt::poses::CPose3D() - T_SC()));  // T_WS
		scene.insert(cloud);
	}

	if (pipe_)
	{
		const auto& g = pipe_->grids();
		const double vs = g.params().voxel_size;
		if (layers_.tier0)
		{
			auto o = CSetOfObjects::Create();
			g.occupancy()->getVisualizationInto(*o);  // blue, P(O) > 0.5
			scene.insert(o);
		}
		if (layers_.tier1)
			scene.insert(voxelCubes(g.background()->movingCells(), 1.15 * vs,
			                        mrpt::img::TColor(255, 255, 0),
			                        "tier1_moving"));
		if (layers_.tier2)
			scene.insert(voxelCubes(g.flow()->movingCells(), 1.3 * vs,
			                        mrpt::img::TColor(255, 0, 0),
			                        "tier2_moving"));
	}

	if (layers_.estimated && est_.size() > 1)
		scene.insert(
		    polyline(est_, {}, mrpt::img::TColor(0, 220, 220), "estimated"));
	if (layers_.groundTruth && gt_.size() > 1)
	{
		// Ground truth aligned to the estimate at the first frame shown.
		mrpt::poses::CPose3D align;
		if (!est_.empty())
		{
			const auto& g0 = *std::min_element(
			    gt_.begin(), gt_.end(),
			    [&](const StampedPose& a, const StampedPose& b) {
				    return std::abs(a.t - est_.front().t) <
				           std::abs(b.t - est_.front().t);
			    });
			align = est_.front().T_WC + (mrpt::poses::CPose3D() - g0.T_WC);
		}
		scene.insert(
		    polyline(gt_, align, mrpt::img::TColor(0, 200, 0), "ground_truth"));
	}
	if (frame_)
	{
		auto cam = stock_objects::CornerXYZSimple(0.15f, 3.0f);
		cam->setName("camera");
		cam->setPose(T_WC);
		scene.insert(cam);
	}
}

ViewCamera ReplayController::suggestedCamera() const
{
	ViewCamera c;
	const mrpt::poses::CPose3D T_WC = currentPose();
	// Look at a point 2 m in front of the camera, from behind and above.
	const auto p = T_WC.composePoint(mrpt::math::TPoint3D(0, 0, 2.0));
	c.pointX = static_cast<float>(p.x);
	c.pointY = static_cast<float>(p.y);
	c.pointZ = static_cast<float>(p.z);
	const auto fwd = T_WC.rotateVector(mrpt::math::TVector3D(0, 0, 1));
	c.azimuthDeg = static_cast<float>(mrpt::RAD2DEG(std::atan2(fwd.y, fwd.x))) +
	               180.0f + 25.0f;
	c.elevationDeg = 40;
	c.zoom = 6.5f;
	return c;
}

mrpt::img::CImage ReplayController::renderOffscreen(const ViewCamera& vc,
                                                    int width, int height) const
{
	mrpt::opengl::COpenGLScene scene;
	fillScene(scene);
	mrpt::opengl::CFBORender fbo(width, height);
	auto& cam = fbo.getCamera(scene);
	cam.setPointingAt(vc.pointX, vc.pointY, vc.pointZ);
	cam.setZoomDistance(vc.zoom);
	cam.setAzimuthDegrees(vc.azimuthDeg);
	cam.setElevationDegrees(vc.elevationDeg);
	mrpt::img::CImage img;
	fbo.render_RGB(scene, img);
	return img;
}

}  // namespace bims::viewer
