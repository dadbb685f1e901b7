// The viewer's main window: a thin wx shell over bims::viewer::ReplayController
// (all logic and its tests live in libs/viewer).
#pragma once

#include <bims/viewer/controller.h>

#include <wx/wx.h>

#include <array>
#include <chrono>
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
	bool paused = false;     ///< start paused (default: play)
	double speed = 1;        ///< replay speed
	int frames = -1;         ///< step this many frames at start (-1: none)
	std::string screenshot;  ///< write the 3D view there, then quit
	bool keepOpen = false;   ///< stay open after --screenshot
	std::string pngDir;      ///< write a PNG of the 3D view per frame
	int width = 1280, height = 800;  ///< window size [px]
};

class ViewerFrame : public wxFrame
{
 public:
	explicit ViewerFrame(const AppOptions& opt);
	/** Exit code for main() (non-zero when a --screenshot failed). */
	static int exitCode;

 private:
	void buildMenus();
	void buildLayout();
	void open(const viewer::ViewerOptions& vo);
	void refreshViews(bool resetCamera = false);
	void updateControls();
	void onTimer(wxTimerEvent&);
	void placeSash();  ///< 3/5 of the width until the user drags the sash
	void onPlayPause(wxCommandEvent&);
	void onStep(wxCommandEvent&);
	void onRestart(wxCommandEvent&);
	void onSlider(wxCommandEvent&);
	void onSpeed(wxCommandEvent&);
	void onOpen(wxCommandEvent&);
	void onOpenResults(wxCommandEvent&);
	void onScreenshot(wxCommandEvent&);
	void onPngSequence(wxCommandEvent&);
	void onLayer(wxCommandEvent&);
	void onAbout(wxCommandEvent&);
	void startBatchScreenshot();
	void showError(const std::string& what);

	AppOptions opt_;
	std::unique_ptr<viewer::ReplayController> ctl_;
	SceneCanvas* canvas_ = nullptr;
	std::array<ImagePanel*, 5> panels_{};
	wxSlider* slider_ = nullptr;
	wxButton* playBtn_ = nullptr;
	wxChoice* speedChoice_ = nullptr;
	wxStaticText* frameLabel_ = nullptr;
	wxTimer timer_;
	wxTimer batchTimer_;
	std::chrono::steady_clock::time_point lastTick_;
	std::string pngDir_;
	int batchWaitTicks_ = 0;
	bool batchCaptureRequested_ = false;
	wxSplitterWindow* split_ = nullptr;
	bool sashMovedByUser_ = false;  ///< the sash no longer follows resizes
};

}  // namespace bims::viewer_app
