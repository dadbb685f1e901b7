#include <bims/apps/app.h>
#include <bims/apps/grab_run.h>
#include <bims/apps/output_checks.h>
#include <bims/common/config.h>
#include <bims/common/share.h>
#include <bims/pipeline/mask_overlay.h>

#include <mrpt/gui/CDisplayWindow.h>
#include <mrpt/system/filesystem.h>

#include <cstdio>
#include <cstdlib>
#include <iostream>
#include <opencv2/imgproc.hpp>

namespace bims::apps
{
mrpt::img::CImage preview(const mrpt::obs::CObservation3DRangeScan& scan,
                          const cv::Mat& mask)
{
	if (!scan.hasIntensityImage) return {};
	const cv::Mat bgr =
	    pipeline::overlayMoving(scan.intensityImage.asCvMatRef(), mask);
	return mrpt::img::CImage(bgr, mrpt::img::DEEP_COPY);
}

GrabbedFrames::GrabbedFrames(std::unique_ptr<pipeline::LiveSegmentation> seg,
                             std::shared_ptr<mrpt::gui::CDisplayWindow> win,
                             size_t maxFrames, bool progress)
    : seg_(std::move(seg)),
      win_(std::move(win)),
      bar_("bims-grab", maxFrames, progress)
{
}

void GrabbedFrames::onSegmented(const source::SourceFrame& f,
                                const pipeline::FrameResult& r)
{
	if (win_ && win_->isOpen()) win_->showImage(preview(*f.scan, r.mask));
	char b[96];
	std::snprintf(b, sizeof(b), "%zu moving voxels, %.0f ms", r.movingVoxels,
	              r.ms.total);
	segmented_ = b;
}

void GrabbedFrames::add(const mrpt::obs::CObservation3DRangeScan::Ptr& scan,
                        const std::vector<mrpt::obs::CObservationIMU::Ptr>& imu)
{
	const auto onSeg = [this](const auto& f, const auto& r)
	{ onSegmented(f, r); };
	std::string extra;
	if (seg_)
	{
		try
		{
			for (const auto& m : imu) seg_->push(m, onSeg);
			seg_->push(scan, onSeg);
			extra = segmented_;
		}
		catch (const std::exception& e)
		{
			std::cerr << "bims-grab: segmentation: " << e.what() << "\n";
		}
	}
	else if (win_ && win_->isOpen())
		win_->showImage(preview(*scan, cv::Mat()));
	bar_.update(++n_, extra);
}

void GrabbedFrames::finishSegmentation()
{
	try
	{
		if (seg_)  // the frames left
			seg_->finish([this](const auto& f, const auto& r)
			             { onSegmented(f, r); });
	}
	catch (const std::exception& e)
	{
		std::cerr << "bims-grab: segmentation: " << e.what() << "\n";
	}
}

GrabApp::GrabApp(const GrabOptions& o) : o_(o)
{
	if (o.maxFrames < 0) throw UsageError("--max-frames must be >= 0");
	// the window before any sensor: no display fails here, before the IMU
	// is recorded
	if (o.viewer)
	{
		const char* display = std::getenv("DISPLAY");
		if (!display || !*display)
			throw std::runtime_error(
			    "--viewer needs a display (DISPLAY is not set); grab without "
			    "--viewer, or under X (e.g. xvfb-run)");
		win_ = mrpt::gui::CDisplayWindow::Create("bims-grab", 640, 480);
		if (!win_->isOpen())
			throw std::runtime_error(
			    std::string("--viewer: cannot open a window on display '") +
			    display + "'");
	}
	if (!mrpt::system::fileExists(o.grabIni))
		throw std::runtime_error("cannot open '" + o.grabIni + "'");

	ini_ = openIniFile(o.grabIni);
	grabber_ =
	    std::make_unique<grab::Grabber>(*ini_);  // throws without devices
	// the files its .ini names are inputs too (a replayed IMU rawlog)
	checkOutputsSpareInputs(grabber_->inputFiles(), {o.out});
	for (const auto& s : grabber_->describe())
		std::cerr << "bims-grab: " << s << "\n";

	std::unique_ptr<pipeline::LiveSegmentation> seg;
	if (o.liveSegmentation)
	{
		const std::string expIni =
		    o.experimentIni.empty() ? defaultExperimentIni() : o.experimentIni;
		pipeline::ExperimentConfig exp;
		if (!expIni.empty()) exp.loadFromFile(expIni);
		std::cerr << "bims-grab: live segmentation: "
		          << parametersSource(expIni) << "\n";
		seg = std::make_unique<pipeline::LiveSegmentation>(exp, "bims-grab",
		                                                   "live input");
	}
	out_ = std::make_unique<RawlogWriter>(o.out, 0);  // plain: flushable
	std::cerr << "bims-grab: writing " << o.out << " (Ctrl-C to stop)\n";
	frames_ = std::make_unique<GrabbedFrames>(
	    std::move(seg), win_, static_cast<size_t>(o.maxFrames), o.progress);
}

GrabApp::~GrabApp() = default;

int GrabApp::run()
{
	static const std::atomic<bool> never{false};
	const auto st = grabber_->run(
	    *out_, o_.stop ? *o_.stop : never, static_cast<size_t>(o_.maxFrames),
	    [this](const auto& scan, const auto& imu) { frames_->add(scan, imu); });
	frames_->finishSegmentation();
	out_->close();
	frames_->finishProgress();
	std::fprintf(stderr,
	             "bims-grab: %zu RGB-D frames, %zu IMU samples in %.1f s (%s) "
	             "-> %s\n",
	             st.frames, st.imu, st.seconds, st.stopReason.c_str(),
	             o_.out.c_str());
	const bool clean =
	    st.stopReason == "stopped" || st.stopReason == "max_frames";
	if (!clean)
		std::fprintf(stderr,
		             "bims-grab: error: grabbing stopped: %s (the rawlog holds "
		             "everything up to there)\n",
		             st.stopReason.c_str());
	return clean ? 0 : 1;
}

}  // namespace bims::apps
