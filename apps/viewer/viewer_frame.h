// The viewer's main window: a thin wx shell over bims::viewer::ReplayWorker
// (the replay and the pipeline on a thread of their own; all logic and its
// tests live in libs/viewer). The GUI thread only draws the newest view.
#pragma once

#include <bims/viewer/replay_worker.h>

#include <wx/wx.h>

#include <array>
#include <memory>
#include <string>

class wxSlider;
class wxChoice;
class wxSplitterWindow;

namespace bims::viewer_app
{
class SceneCanvas;
class ImagePanel;

/** Command-line options of bims-viewer. */
struct AppOptions
{
	viewer::ViewerOptions viewer;
	viewer::LayerVisibility layers;  ///< --layers
	viewer::PlayMode mode = viewer::PlayMode::RealTime;
	bool paused = false;     ///< start paused (default: play)
	double speed = 1;        ///< replay speed
	int frames = -1;         ///< step this many frames at start (-1: none)
	std::string screenshot;  ///< write the 3D view there, then quit
	bool keepOpen = false;   ///< stay open after --screenshot
	std::string pngDir;      ///< write a PNG of the 3D view per frame
	std::string stateFile;   ///< write the window's state after each draw
	int width = 1280, height = 800;  ///< window size [px]
};

class ViewerFrame : public wxFrame
{
 public:
	explicit ViewerFrame(const AppOptions& opt);
	~ViewerFrame() override;
	/** Exit code for main() (non-zero when a --screenshot failed). */
	static int exitCode;
	/** Set once a frame was created (wx initialised with a display). */
	static bool created;

 private:
	void buildMenus();
	void buildLayout();
	void open(const viewer::ViewerOptions& vo);
	void draw(const std::shared_ptr<const viewer::FrameView>& v);
	void showLayers();
	void updateControls();
	void writeState();
	void onTimer(wxTimerEvent&);
	void placeSash();  ///< 1/2 of the width until the user drags the sash
	void onPlayPause(wxCommandEvent&);
	void onStep(wxCommandEvent&);
	void onRestart(wxCommandEvent&);
	void onSliderReleased();
	void onSpeed(wxCommandEvent&);
	void onOpen(wxCommandEvent&);
	void onOpenResults(wxCommandEvent&);
	void onScreenshot(wxCommandEvent&);
	void onPngSequence(wxCommandEvent&);
	void onLayer(wxCommandEvent&);
	void onAbout(wxCommandEvent&);
	void batchScreenshot();
	void showError(const std::string& what);

	AppOptions opt_;
	std::unique_ptr<viewer::ReplayWorker> worker_;
	std::shared_ptr<const viewer::FrameView> shown_;  ///< drawn last
	uint64_t ackPending_ = 0;  ///< drawn, not yet told to the worker
	bool cameraSet_ = false;   ///< the first view set the whole camera
	bool follow_ = true;       ///< the look-at point follows the sensor
	SceneCanvas* canvas_ = nullptr;
	std::array<ImagePanel*, viewer::kPanelCount> panels_{};
	wxSlider* slider_ = nullptr;
	bool sliderHeld_ = false;  ///< the user drags the thumb
	wxButton* playBtn_ = nullptr;
	wxChoice* speedChoice_ = nullptr;
	wxStaticText* frameLabel_ = nullptr;
	wxTimer timer_;
	std::string pngDir_;
	std::string stateWritten_;  ///< the --state-file's last text
	int batchTarget_ = 0;
	int batchWaitTicks_ = 0;
	bool batchCaptureRequested_ = false;
	wxSplitterWindow* split_ = nullptr;
	bool sashMovedByUser_ = false;  ///< the sash no longer follows resizes
};

}  // namespace bims::viewer_app
