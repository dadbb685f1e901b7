// bims-maps-figure's picture (figure.h).
#include "figure.h"

#include <bims/common/frames.h>
#include <bims/eval/association.h>
#include <bims/io/frame_files.h>
#include <bims/io/image_file.h>
#include <bims/io/rawlog.h>
#include <bims/io/trajectory.h>
#include <bims/maps/export.h>
#include <bims/maps/motion_grids.h>
#include <filesystem>

#include <mrpt/img/CImage.h>
#include <mrpt/obs/CObservation3DRangeScan.h>
#include <mrpt/opengl/CFBORender.h>
#include <mrpt/opengl/COctoMapVoxels.h>
#include <mrpt/opengl/COpenGLScene.h>
#include <mrpt/opengl/CSetOfObjects.h>

#include <opencv2/imgcodecs.hpp>

#include <cstdio>
#include <iostream>
#include <stdexcept>
#include <vector>

namespace
{
/** A scan and its ground-truth pose at most this far apart [s] (TUM's
 * associate.py default). */
constexpr double kMaxPoseDifference = 0.02;
}  // namespace

int renderGridsFigure(const FigureOptions& o)
{
	const std::string& gt = o.gt;
	const std::string gtFile = gt + "/groundtruth.txt";
	const auto traj = bims::loadTumTrajectory(gtFile);
	// The poses paired with the scans by time stamp (eval's association),
	// never by line: another recording's ground truth is an error.
	std::vector<double> scanT, gtT;
	{
		bims::RawlogReader first(o.rawlog);
		while (auto obs = first.next())
			if (IS_CLASS(*obs, mrpt::obs::CObservation3DRangeScan))
			{
				scanT.push_back(mrpt::Clock::toDouble(obs->timestamp));
				if (int(scanT.size()) >= o.frames) break;
			}
	}
	for (const auto& p : traj) gtT.push_back(p.t);
	const auto pairs =
	    bims::eval::associateGreedy(scanT, gtT, kMaxPoseDifference);
	if (pairs.empty())
	{
		char span[160] = "no 3D scan";
		if (!scanT.empty() && !gtT.empty())
			std::snprintf(span, sizeof(span),
			              "its scans at %.3f..%.3f s, the poses at %.3f..%.3f "
			              "s",
			              scanT.front(), scanT.back(), gtT.front(), gtT.back());
		char within[32];
		std::snprintf(within, sizeof(within), "%g", kMaxPoseDifference);
		throw std::runtime_error(
		    gtFile + ": no pose within " + within + " s of any of the first " +
		    std::to_string(scanT.size()) + " 3D scans of " + o.rawlog + " (" +
		    span + "): the ground truth of another recording?");
	}
	std::vector<long> poseOf(scanT.size(), -1);
	for (const auto& [i, j] : pairs) poseOf[i] = long(j);

	bims::maps::GridParams p;
	p.voxel_size = o.voxel;
	p.decay = bims::maps::DecayMode::Raycast;
	p.raycast_target = bims::maps::RayTarget::Voxels;
	bims::maps::MotionGrids grids(p);
	bims::RawlogReader r(o.rawlog);
	int k = 0, used = 0;
	long lastPose = 0;
	while (auto obs = r.next())
	{
		auto scan =
		    std::dynamic_pointer_cast<mrpt::obs::CObservation3DRangeScan>(obs);
		if (!scan) continue;
		if (k >= int(scanT.size())) break;
		const long pose = poseOf[size_t(k)];
		if (pose < 0)
		{
			++k;  // no pose at its time
			continue;
		}
		lastPose = pose;
		const auto T_WS = traj[size_t(pose)].T_WC + (-bims::T_SC());
		const std::string name = "/masks/" + bims::frameFileName(k);
		const cv::Mat m =
		    std::filesystem::exists(gt + name)
		        ? bims::readImageFile(gt + name, cv::IMREAD_GRAYSCALE, "mask")
		        : cv::Mat();
		bims::maps::PixelLabels labels;
		if (!m.empty())
		{
			labels = bims::maps::PixelLabels(m.cols, m.rows, 0);
			for (int v = 0; v < m.rows; ++v)
				for (int u = 0; u < m.cols; ++u)
					if (m.at<uint8_t>(v, u)) labels.at(u, v) = 1;
		}
		grids.processFrame(*scan, T_WS,
		                   labels.label.empty() ? nullptr : &labels);
		++k;
		++used;
	}
	if (used < k)
		std::cout << k - used << " of the first " << k
		          << " 3D scans have no ground-truth pose within "
		          << kMaxPoseDifference << " s: skipped\n";
	mrpt::opengl::COpenGLScene scene;
	auto all = mrpt::opengl::CSetOfObjects::Create();
	// Tier 0 without the voxels tier 1/2 flag (they coincide and would
	// be hidden), drawn like COccupancyBayesGrid::getVisualizationInto.
	auto vox = mrpt::opengl::COctoMapVoxels::Create();
	vox->resizeVoxelSets(1);
	for (const auto& key : bims::maps::staticOccupiedKeys(
	         *grids.occupancy(), grids.background().get()))
		vox->push_back_Voxel(0, mrpt::opengl::COctoMapVoxels::TVoxel(
		                            grids.occupancy()->centerOf(key), o.voxel,
		                            mrpt::img::TColor(0, 0, 255, 255)));
	vox->setVisualizationMode(mrpt::opengl::COctoMapVoxels::FIXED);
	vox->showGridLines(false);
	all->insert(vox);
	// Tier 1 (yellow) where tier 2 does not agree, tier 2 (red) on top.
	auto t12 = mrpt::opengl::COctoMapVoxels::Create();
	t12->resizeVoxelSets(1);
	const auto& c1 = grids.background()->lastCells();
	const auto& l1 = grids.background()->lastPosterior();
	const auto& l2 = grids.flowConsistency()->lastPosterior();
	size_t n1 = 0, n2 = 0;
	for (size_t i = 0; i < c1.size(); ++i)
	{
		if (!(l1[i] > 0 || l2[i] > 0)) continue;
		const bool red = l2[i] > 0;
		(red ? n2 : n1)++;
		t12->push_back_Voxel(0, mrpt::opengl::COctoMapVoxels::TVoxel(
		                            grids.occupancy()->centerOf(c1[i]), o.voxel,
		                            red ? mrpt::img::TColor(255, 0, 0, 255)
		                                : mrpt::img::TColor(255, 255, 0, 255)));
	}
	t12->setVisualizationMode(mrpt::opengl::COctoMapVoxels::FIXED);
	t12->showGridLines(false);
	all->insert(t12);
	std::cout << "last frame: " << n2 << " voxels moving by tier 2 (red), "
	          << n1 << " by tier 1 only (yellow)\n";
	scene.insert(all);
	mrpt::opengl::CFBORender fbo(1000, 750);
	auto& cam = fbo.getCamera(scene);
	const auto at = traj[size_t(lastPose)].T_WC.translation();
	cam.setPointingAt(float(at.x + 2.0), float(at.y), float(at.z - 0.3));
	cam.setZoomDistance(5);
	cam.setAzimuthDegrees(180);
	cam.setElevationDegrees(25);
	mrpt::img::CImage img;
	fbo.render_RGB(scene, img);
	img.saveToFile(o.out);
	std::cout << used << " frames; " << grids.occupancy()->asString() << "\n"
	          << grids.flowConsistency()->asString() << "\nwrote " << o.out
	          << "\n";
	return 0;
}
