// bims-maps-figure's picture (figure.h).
#include "figure.h"

#include <bims/common/frame_files.h>
#include <bims/common/frames.h>
#include <bims/common/image_file.h>
#include <bims/common/rawlog.h>
#include <bims/common/trajectory.h>
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

int renderGridsFigure(const FigureOptions& o)
{
	const std::string& gt = o.gt;
	const auto traj = bims::loadTumTrajectory(gt + "/groundtruth.txt");
	bims::maps::GridParams p;
	p.voxel_size = o.voxel;
	p.decay = bims::maps::DecayMode::Raycast;
	p.raycast_target = bims::maps::RayTarget::Voxels;
	bims::maps::MotionGrids grids(p);
	bims::RawlogReader r(o.rawlog);
	int k = 0;
	while (auto obs = r.next())
	{
		auto scan =
		    std::dynamic_pointer_cast<mrpt::obs::CObservation3DRangeScan>(obs);
		if (!scan) continue;
		if (k >= o.frames || k >= int(traj.size())) break;
		const auto T_WS = traj[k].T_WC + (-bims::T_SC());
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
	}
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
	const auto at = traj[std::max(0, k - 1)].T_WC.translation();
	cam.setPointingAt(float(at.x + 2.0), float(at.y), float(at.z - 0.3));
	cam.setZoomDistance(5);
	cam.setAzimuthDegrees(180);
	cam.setElevationDegrees(25);
	mrpt::img::CImage img;
	fbo.render_RGB(scene, img);
	img.saveToFile(o.out);
	std::cout << k << " frames; " << grids.occupancy()->asString() << "\n"
	          << grids.flowConsistency()->asString() << "\nwrote " << o.out
	          << "\n";
	return 0;
}
