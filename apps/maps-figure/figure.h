// bims-maps-figure's picture: the three grids run over a rawlog with
// ground-truth poses and rendered headless with the paper's Fig. 4
// colouring (tier 0 blue, tier 1 yellow, tier 2 red). Ground-truth moving
// masks stand in for the flow labels (Diff on the mask, notDiff
// elsewhere): a picture of the grids, not of the flow module.
#pragma once

#include <string>

struct FigureOptions
{
	std::string rawlog;   ///< IN.rawlog
	std::string gt;       ///< its ground truth (groundtruth.txt, masks/)
	std::string out;      ///< OUT.png
	int frames = 60;      ///< frames to integrate
	double voxel = 0.05;  ///< voxel size [m]
};

/** Integrates the first \a o.frames 3D scans, each at the ground-truth
 * pose paired with it by time stamp (eval::associateGreedy, at most 0.02 s
 * apart; a scan without one is skipped), and writes the picture; prints
 * what it drew. Throws naming both files when no scan has a pose (the
 * ground truth of another recording). Returns the exit code (0). */
int renderGridsFigure(const FigureOptions& o);
