// The 3D view: registered cloud, the three tiers, trajectories, built as a
// FrameView.
#include <bims/common/frames.h>
#include <bims/eval/rgbd_frame.h>
#include <bims/viewer/controller.h>
#include <bims/viewer/panels.h>

#include <mrpt/maps/CColouredPointsMap.h>
#include <mrpt/obs/T3DPointsProjectionParams.h>
#include <mrpt/opengl/CFBORender.h>
#include <mrpt/opengl/CGridPlaneXY.h>
#include <mrpt/opengl/COctoMapVoxels.h>
#include <mrpt/opengl/CPointCloud.h>
#include <mrpt/opengl/CPointCloudColoured.h>
#include <mrpt/opengl/CSetOfLines.h>
#include <mrpt/opengl/CSetOfObjects.h>
#include <mrpt/opengl/stock_objects.h>

#include <opencv2/imgproc.hpp>

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

/** The scan's points in {W}, coloured by its image (a grey shade for a
 * depth-only scan) with the pixels of \a mask pure red. MRPT unprojects and
 * colours them (its camera model, one home), from a copy of the scan whose
 * image is the tinted one. */
mrpt::opengl::CPointCloudColoured::Ptr registeredCloud(
    const mrpt::obs::CObservation3DRangeScan& scan, const cv::Mat& mask,
    const mrpt::poses::CPose3D& T_WC, int decimation)
{
	const cv::Size size(static_cast<int>(scan.rangeImage.cols()),
	                    static_cast<int>(scan.rangeImage.rows()));
	cv::Mat bgr = intensityBgr(scan);
	if (bgr.empty())
		bgr = cv::Mat(size, CV_8UC3, cv::Scalar(170, 170, 170));
	else if (bgr.size() != size)
		cv::resize(bgr, bgr, size, 0, 0, cv::INTER_AREA);
	else
		bgr = bgr.clone();
	if (!mask.empty())
	{
		cv::Mat m = mask;
		if (m.size() != size) cv::resize(m, m, size, 0, 0, cv::INTER_NEAREST);
		bgr.setTo(cv::Scalar(0, 0, 255), m);
	}
	mrpt::obs::CObservation3DRangeScan tinted = scan;
	eval::attachColour(tinted, bgr);
	mrpt::maps::CColouredPointsMap pts;
	mrpt::obs::T3DPointsProjectionParams pp;
	pp.decimation =
	    (size.width % decimation == 0 && size.height % decimation == 0)
	        ? decimation
	        : 1;
	tinted.unprojectInto(pts, pp);  // {S}, sensorPose not applied
	auto cloud = mrpt::opengl::CPointCloudColoured::Create();
	cloud->setName("cloud");
	cloud->loadFromPointsMap(&pts);
	cloud->setPointSize(2.0f);
	cloud->setPose(T_WC + (mrpt::poses::CPose3D() - T_SC()));  // T_WS
	return cloud;
}

/** Tier 0's occupied voxels as small faint points: the static scene as
 * context, never hiding what moves. */
mrpt::opengl::CPointCloud::Ptr faintVoxels(
    const std::vector<mrpt::math::TPoint3D>& centres)
{
	auto pts = mrpt::opengl::CPointCloud::Create();
	pts->setName("tier0_occupancy");
	pts->setColor_u8(mrpt::img::TColor(70, 100, 210));
	pts->setPointSize(2.0f);
	for (const auto& c : centres)
		pts->insertPoint(static_cast<float>(c.x), static_cast<float>(c.y),
		                 static_cast<float>(c.z));
	return pts;
}
}  // namespace

std::shared_ptr<FrameView> ReplayController::view() const
{
	using namespace mrpt::opengl;
	auto v = std::make_shared<FrameView>();
	v->frame = cur_;
	v->frameCount = frameCount();
	v->mask = currentMask();
	v->panels = panels();
	v->counter = counterText();
	v->status = statusText();
	v->follow = suggestedCamera();

	const mrpt::poses::CPose3D T_WC = currentPose();
	auto& L = v->layers;
	if (layers_[Layer::Cloud] && frame_)
		L[size_t(Layer::Cloud)] = registeredCloud(*frame_->scan, currentMask(),
		                                          T_WC, opt_.cloudDecimation);
	if (pipe_)
	{
		const auto& g = pipe_->grids();
		const double vs = g.params().voxel_size;
		if (layers_[Layer::Tier0])
			L[size_t(Layer::Tier0)] =
			    faintVoxels(g.occupancy()->cellsAbove(0.5));
		if (layers_[Layer::Tier1])
			L[size_t(Layer::Tier1)] =
			    voxelCubes(g.background()->movingCells(), 1.15 * vs,
			               mrpt::img::TColor(255, 255, 0), "tier1_moving");
		if (layers_[Layer::Tier2])
			L[size_t(Layer::Tier2)] =
			    voxelCubes(g.flowConsistency()->movingCells(), 1.3 * vs,
			               mrpt::img::TColor(255, 0, 0), "tier2_moving");
	}
	if (layers_[Layer::Estimated] && est_.size() > 1)
		L[size_t(Layer::Estimated)] =
		    polyline(est_, {}, mrpt::img::TColor(0, 220, 220), "estimated");
	if (layers_[Layer::GroundTruth] && gt_.size() > 1)
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
		L[size_t(Layer::GroundTruth)] =
		    polyline(gt_, align, mrpt::img::TColor(0, 200, 0), "ground_truth");
	}
	if (frame_)
	{
		auto cam = stock_objects::CornerXYZSimple(0.15f, 3.0f);
		cam->setName("camera");
		cam->setPose(T_WC);
		v->sensor = cam;
	}
	return v;
}

void ReplayController::fillScene(mrpt::opengl::COpenGLScene& scene) const
{
	showView(scene, *view(), layers_);
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
