// bims-grab's run (docs/grab.md): the sensors of a grab .ini (libs/grab's
// Grabber) into a flushed rawlog, each frame optionally segmented as it
// comes (pipeline::LiveSegmentation) and shown in a window with its moving
// mask. The program's main reads its command line into GrabOptions,
// installs the stop signals and runs a GrabApp.
#pragma once

#include <bims/apps/progress_bar.h>
#include <bims/grab/grabber.h>
#include <bims/io/rawlog.h>
#include <bims/pipeline/stepper.h>

#include <mrpt/config/CConfigFile.h>
#include <mrpt/img/CImage.h>
#include <opencv2/core.hpp>

#include <atomic>
#include <memory>
#include <string>
#include <vector>

namespace mrpt::gui
{
class CDisplayWindow;
}

namespace bims::apps
{
/** The RGB image of \a scan (grey made BGR) with the pixels of \a mask
 * (when of its size) blended half with red; empty without an image. */
mrpt::img::CImage preview(const mrpt::obs::CObservation3DRangeScan& scan,
                          const cv::Mat& mask);

/** What bims-grab does with every frame written: the live segmentation
 * (optional; its errors printed, never thrown: the grab goes on), the
 * window (optional), the progress line ("N moving voxels, T ms" of the
 * last frame segmented). */
class GrabbedFrames
{
 public:
	GrabbedFrames(std::unique_ptr<pipeline::LiveSegmentation> seg,
	              std::shared_ptr<mrpt::gui::CDisplayWindow> win,
	              size_t maxFrames, bool progress);
	/** The callback of Grabber::run. */
	void add(const mrpt::obs::CObservation3DRangeScan::Ptr& scan,
	         const std::vector<mrpt::obs::CObservationIMU::Ptr>& imu);
	/** The end of the input: segments the frames left. */
	void finishSegmentation();
	/** The progress line's last line. */
	void finishProgress() { bar_.finish(); }
	size_t frames() const { return n_; }
	/** The last frame segmented, in words ("" before the first). */
	const std::string& lastSegmented() const { return segmented_; }

 private:
	void onSegmented(const source::SourceFrame& f,
	                 const pipeline::FrameResult& r);

	std::unique_ptr<pipeline::LiveSegmentation> seg_;
	std::shared_ptr<mrpt::gui::CDisplayWindow> win_;
	ProgressBar bar_;
	size_t n_ = 0;
	std::string segmented_;
};

/** What bims-grab's command line gives. */
struct GrabOptions
{
	std::string grabIni;  ///< the sensors (apps/grab/examples/*.ini)
	std::string out;      ///< output rawlog
	int maxFrames = 0;    ///< stop after N RGB-D frames (0: [global])
	bool liveSegmentation = false;
	/** experiment .ini of the live segmentation ("": share/bims's) */
	std::string experimentIni;
	bool viewer = false;                      ///< a window with the frames
	bool progress = true;                     ///< progress lines on stderr
	const std::atomic<bool>* stop = nullptr;  ///< true: stop cleanly
};

class GrabApp
{
 public:
	/** Checks the options, opens the window (before any sensor: no display
	 * fails here), the sensors (throws without devices), the segmentation
	 * and the output rawlog, naming each on stderr. */
	explicit GrabApp(const GrabOptions& o);
	~GrabApp();
	/** Grabs until stopped, max_frames or an error; closes the rawlog and
	 * prints what was grabbed. Returns the exit code: 0 when stopped or at
	 * max_frames, 1 when grabbing failed (the rawlog holds everything up to
	 * there). */
	int run();

 private:
	GrabOptions o_;
	std::shared_ptr<mrpt::gui::CDisplayWindow> win_;
	std::unique_ptr<mrpt::config::CConfigFile> ini_;
	std::unique_ptr<grab::Grabber> grabber_;
	std::unique_ptr<RawlogWriter> out_;
	std::unique_ptr<GrabbedFrames> frames_;
};

}  // namespace bims::apps
