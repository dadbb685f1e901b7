#include "viewer_frame.h"

#include <bims/io/frame_files.h>
#include <bims/io/json.h>
#include <bims/io/output_paths.h>

#include <wx/aboutdlg.h>
#include <wx/dirdlg.h>
#include <wx/filedlg.h>
#include <wx/slider.h>
#include <wx/splitter.h>

#include <iostream>

#include "image_panel.h"
#include "scene_canvas.h"

namespace bims::viewer_app
{
int ViewerFrame::exitCode = 0;
bool ViewerFrame::created = false;

namespace
{
enum
{
	ID_OPEN_RESULTS = wxID_HIGHEST + 1,
	ID_SCREENSHOT,
	ID_PNG_SEQ,
	ID_LAYER_FIRST,  // one per viewer::Layer
	ID_LAYER_LAST = ID_LAYER_FIRST + int(viewer::kLayerCount) - 1,
	ID_FOLLOW,
	ID_PLAY,
	ID_STEP,
	ID_RESTART,
	ID_MODE_REALTIME,
	ID_MODE_EVERY,
	ID_SLIDER,
	ID_SPEED
};
const double kSpeeds[] = {0.1, 0.25, 0.5, 1, 2, 4, 8};

/** A widget's rectangle on the screen as [x, y, w, h]. */
Json screenRect(const wxWindow* w)
{
	const wxRect r = w->GetScreenRect();
	return Json::array({r.x, r.y, r.width, r.height});
}
}  // namespace

ViewerFrame::ViewerFrame(const AppOptions& opt)
    : wxFrame(nullptr, wxID_ANY, "bims-viewer", wxDefaultPosition,
              wxSize(opt.width, opt.height)),
      opt_(opt),
      timer_(this)
{
	created = true;
	buildMenus();
	buildLayout();
	CreateStatusBar(2);
	const int widths[] = {-3, -2};
	SetStatusWidths(2, widths);
	SetStatusText("File > Open rawlog... to start");
	Bind(wxEVT_TIMER, &ViewerFrame::onTimer, this, timer_.GetId());
	pngDir_ = opt_.pngDir;
	if (!pngDir_.empty()) makeDirs(pngDir_);
	if (!opt_.viewer.rawlog.empty())
	{
		try
		{
			open(opt_.viewer);
		}
		catch (const std::exception& e)
		{
			if (!opt_.screenshot.empty())
			{
				std::cerr << "bims-viewer: error: " << e.what() << "\n";
				exitCode = 1;
				CallAfter([this] { Close(true); });
				return;
			}
			showError(e.what());
		}
	}
	if (worker_)
	{
		worker_->setSpeed(opt_.speed);
		// the speed box shows --speed when it is one of its entries
		for (size_t i = 0; i < std::size(kSpeeds); ++i)
			if (kSpeeds[i] == opt_.speed) speedChoice_->SetSelection(int(i));
		// --max-frames N: frame N-1; --paused: the first frame; else play
		batchTarget_ = std::max(0, opt_.frames - 1);
		if (!opt_.screenshot.empty() || opt_.paused || opt_.frames > 0)
			worker_->seek(static_cast<size_t>(batchTarget_));
		else
			worker_->play(true);
	}
	timer_.Start(20);
}

ViewerFrame::~ViewerFrame()
{
	timer_.Stop();
	worker_.reset();  // stops the replay thread before the widgets go
}

void ViewerFrame::buildMenus()
{
	auto* file = new wxMenu;
	file->Append(wxID_OPEN, "&Open rawlog...\tCtrl+O");
	file->Append(ID_OPEN_RESULTS, "Open bims-run &results folder...");
	file->AppendSeparator();
	file->Append(ID_SCREENSHOT, "Export &screenshot...\tCtrl+S");
	file->AppendCheckItem(ID_PNG_SEQ, "Export &PNG sequence...");
	file->AppendSeparator();
	file->Append(wxID_EXIT, "&Quit\tCtrl+Q");
	auto* view = new wxMenu;
	for (size_t i = 0; i < viewer::kLayerCount; ++i)
		view->AppendCheckItem(ID_LAYER_FIRST + int(i),
		                      viewer::layerTitle(viewer::Layer(i)))
		    ->Check(opt_.layers.on[i]);
	view->AppendSeparator();
	view->AppendCheckItem(ID_FOLLOW, "Camera &follows the sensor")
	    ->Check(follow_);
	auto* play = new wxMenu;
	// Plain keys (GTK accelerators need modifiers): see the char hook.
	play->Append(ID_PLAY, "&Play / Pause (Space)");
	play->Append(ID_STEP, "&Step one frame (Right)");
	play->Append(ID_RESTART, "&Restart (Home)");
	play->AppendSeparator();
	play->AppendRadioItem(ID_MODE_REALTIME,
	                      "Real &time (frames finished while drawing are "
	                      "not drawn)");
	play->AppendRadioItem(ID_MODE_EVERY,
	                      "&Every frame (playback slows to the drawing)");
	play->Check(opt_.mode == viewer::PlayMode::RealTime ? ID_MODE_REALTIME
	                                                    : ID_MODE_EVERY,
	            true);
	auto* help = new wxMenu;
	help->Append(wxID_ABOUT, "&About");
	auto* bar = new wxMenuBar;
	bar->Append(file, "&File");
	bar->Append(view, "&View");
	bar->Append(play, "&Playback");
	bar->Append(help, "&Help");
	SetMenuBar(bar);

	Bind(wxEVT_MENU, &ViewerFrame::onOpen, this, wxID_OPEN);
	Bind(wxEVT_MENU, &ViewerFrame::onOpenResults, this, ID_OPEN_RESULTS);
	Bind(wxEVT_MENU, &ViewerFrame::onScreenshot, this, ID_SCREENSHOT);
	Bind(wxEVT_MENU, &ViewerFrame::onPngSequence, this, ID_PNG_SEQ);
	Bind(
	    wxEVT_MENU, [this](wxCommandEvent&) { Close(true); }, wxID_EXIT);
	Bind(wxEVT_MENU, &ViewerFrame::onAbout, this, wxID_ABOUT);
	Bind(wxEVT_CHAR_HOOK,
	     [this](wxKeyEvent& e)
	     {
		     wxCommandEvent c;
		     switch (e.GetKeyCode())
		     {
			     case WXK_SPACE:
				     onPlayPause(c);
				     break;
			     case WXK_RIGHT:
				     onStep(c);
				     break;
			     case WXK_HOME:
				     onRestart(c);
				     break;
			     default:
				     e.Skip();
		     }
	     });
	Bind(wxEVT_MENU, &ViewerFrame::onPlayPause, this, ID_PLAY);
	Bind(wxEVT_MENU, &ViewerFrame::onStep, this, ID_STEP);
	Bind(wxEVT_MENU, &ViewerFrame::onRestart, this, ID_RESTART);
	Bind(wxEVT_MENU, &ViewerFrame::onLayer, this, ID_LAYER_FIRST,
	     ID_LAYER_LAST);
	Bind(
	    wxEVT_MENU,
	    [this](wxCommandEvent& e)
	    {
		    follow_ = e.IsChecked();
		    if (follow_ && shown_) draw(shown_);
	    },
	    ID_FOLLOW);
	Bind(
	    wxEVT_MENU,
	    [this](wxCommandEvent& e)
	    {
		    opt_.mode = e.GetId() == ID_MODE_REALTIME
		                    ? viewer::PlayMode::RealTime
		                    : viewer::PlayMode::EveryFrame;
		    if (worker_) worker_->setMode(opt_.mode);
		    updateControls();
	    },
	    ID_MODE_REALTIME, ID_MODE_EVERY);
}

void ViewerFrame::buildLayout()
{
	auto* split = new wxSplitterWindow(this, wxID_ANY, wxDefaultPosition,
	                                   wxDefaultSize, wxSP_LIVE_UPDATE);
	canvas_ = new SceneCanvas(split);
	auto* right = new wxPanel(split);
	// Two columns of panels, each keeping its image's aspect ratio inside:
	// at any image size (256x192 to 1280x720) they share the space evenly.
	auto* grid = new wxGridSizer(3, 2, 2, 2);
	for (size_t i = 0; i < panels_.size(); ++i)
	{
		panels_[i] = new ImagePanel(
		    right, viewer::toString(static_cast<viewer::Panel>(i)));
		grid->Add(panels_[i], 1, wxEXPAND);
	}
	// the sixth cell: what the colours of the 3D view mean
	auto* legend = new wxStaticText(right, wxID_ANY,
	                                "3D view\n"
	                                "  red: moving points,\n"
	                                "     tier-2 moving voxels\n"
	                                "  yellow: tier-1 moving voxels\n"
	                                "  faint blue: tier 0 (View menu)\n"
	                                "  cyan: estimate; green: truth\n\n"
	                                "Mouse: drag to orbit, wheel to\n"
	                                "  zoom, shift-drag to pan\n"
	                                "Keys: Space play/pause,\n"
	                                "  Right step, Home restart");
	grid->Add(legend, 1, wxEXPAND | wxALL, 6);
	right->SetSizer(grid);
	split->SplitVertically(canvas_, right, opt_.width / 2);
	split->SetSashGravity(0.5);
	split->SetMinimumPaneSize(100);
	// The frame gets its real size only once shown, and the window manager
	// may resize it after the first events: the sash stays at half the
	// width (placeSash) until the user drags it (a drag is told by
	// SASH_POS_CHANGING, sent only while the mouse moves the sash; wx sends
	// SASH_POS_CHANGED also when it moves the sash itself).
	split_ = split;
	CallAfter([this] { placeSash(); });
	split->Bind(wxEVT_SPLITTER_SASH_POS_CHANGING,
	            [this](wxSplitterEvent& e)
	            {
		            sashMovedByUser_ = true;
		            e.Skip();
	            });
	Bind(wxEVT_SIZE,
	     [this](wxSizeEvent& e)
	     {
		     e.Skip();
		     CallAfter([this] { placeSash(); });
	     });

	// Timeline: play/pause, step, restart, speed, slider, frame counter.
	auto* bar = new wxPanel(this);
	auto* hs = new wxBoxSizer(wxHORIZONTAL);
	playBtn_ =
	    new wxButton(bar, ID_PLAY, "Pause", wxDefaultPosition, wxSize(90, -1));
	hs->Add(playBtn_, 0, wxALL, 2);
	hs->Add(new wxButton(bar, ID_STEP, "Step >|"), 0, wxALL, 2);
	hs->Add(new wxButton(bar, ID_RESTART, "|< Restart"), 0, wxALL, 2);
	wxArrayString speeds;
	for (double s : kSpeeds) speeds.Add(wxString::Format("x%g", s));
	speedChoice_ =
	    new wxChoice(bar, ID_SPEED, wxDefaultPosition, wxDefaultSize, speeds);
	speedChoice_->SetSelection(3);
	hs->Add(speedChoice_, 0, wxALL | wxALIGN_CENTER_VERTICAL, 2);
	slider_ = new wxSlider(bar, ID_SLIDER, 0, 0, 1);
	hs->Add(slider_, 1, wxALL | wxEXPAND, 2);
	frameLabel_ = new wxStaticText(bar, wxID_ANY, "  -/-  ", wxDefaultPosition,
	                               wxSize(110, -1), wxST_NO_AUTORESIZE);
	hs->Add(frameLabel_, 0, wxALL | wxALIGN_CENTER_VERTICAL, 4);
	bar->SetSizer(hs);

	auto* vs = new wxBoxSizer(wxVERTICAL);
	vs->Add(split, 1, wxEXPAND);
	vs->Add(bar, 0, wxEXPAND);
	SetSizer(vs);

	Bind(wxEVT_BUTTON, &ViewerFrame::onPlayPause, this, ID_PLAY);
	Bind(wxEVT_BUTTON, &ViewerFrame::onStep, this, ID_STEP);
	Bind(wxEVT_BUTTON, &ViewerFrame::onRestart, this, ID_RESTART);
	Bind(wxEVT_CHOICE, &ViewerFrame::onSpeed, this, ID_SPEED);
	// The slider follows playback except while the user holds the thumb;
	// it seeks on release (going back re-runs the pipeline from frame 0,
	// on the replay thread: the window stays live meanwhile).
	slider_->Bind(wxEVT_SCROLL_THUMBTRACK,
	              [this](wxScrollEvent&) { sliderHeld_ = true; });
	slider_->Bind(wxEVT_SCROLL_CHANGED,
	              [this](wxScrollEvent&) { onSliderReleased(); });
}

void ViewerFrame::placeSash()
{
	const int want = GetClientSize().x / 2;
	if (!sashMovedByUser_ && split_->GetSashPosition() != want)
		split_->SetSashPosition(want);
}

void ViewerFrame::open(const viewer::ViewerOptions& vo)
{
	wxBusyCursor busy;
	worker_.reset();  // the old replay thread stops first
	shown_.reset();
	ackPending_ = 0;
	cameraSet_ = false;
	worker_ = std::make_unique<viewer::ReplayWorker>(vo, opt_.layers);
	worker_->setMode(opt_.mode);
	opt_.viewer = vo;
	SetTitle("bims-viewer - " + vo.rawlog);
	slider_->SetRange(0, std::max<int>(1, int(worker_->frameCount()) - 1));
	slider_->SetValue(0);
	updateControls();
}

void ViewerFrame::showLayers()
{
	if (!shown_) return;
	viewer::showView(*canvas_->getOpenGLSceneRef(), *shown_, opt_.layers);
}

void ViewerFrame::draw(const std::shared_ptr<const viewer::FrameView>& v)
{
	shown_ = v;
	showLayers();
	const auto& c = v->follow;
	if (!cameraSet_)
	{
		canvas_->setCameraPointing(c.pointX, c.pointY, c.pointZ);
		canvas_->setZoomDistance(c.zoom);
		canvas_->setAzimuthDegrees(c.azimuthDeg);
		canvas_->setElevationDegrees(c.elevationDeg);
		cameraSet_ = v->frame >= 0;
	}
	else if (follow_)  // the look-at point moves with the sensor; the
	                   // user's orbit and zoom stay
		canvas_->setCameraPointing(c.pointX, c.pointY, c.pointZ);
	if (!pngDir_.empty() && v->frame >= 0)
		canvas_->requestCapture(pngDir_ + "/" + bims::frameFileName(v->frame));
	for (size_t i = 0; i < panels_.size(); ++i)
		panels_[i]->setImage(v->panels[i]);
	canvas_->Refresh(false);
	canvas_->Update();  // paint now: the view shown is the view acked
	if (!sliderHeld_) slider_->SetValue(std::max(0L, v->frame));
	frameLabel_->SetLabel("  " + v->counter + "  ");
	ackPending_ = v->seq;
	updateControls();
	writeState();
}

void ViewerFrame::updateControls()
{
	if (!worker_) return;
	const auto st = worker_->state();
	const wxString play = st.playing ? "Pause" : "Play";
	if (playBtn_->GetLabel() != play) playBtn_->SetLabel(play);
	if (shown_) SetStatusText(shown_->status, 0);
	std::string right;
	if (!st.busy.empty())
		right = st.busy;
	else
	{
		right = std::string(st.playing ? "playing " : "paused ") +
		        viewer::toString(st.mode) + ": " +
		        std::to_string(st.processed) + " processed";
		if (st.notDrawn > 0)
			right += ", " + std::to_string(st.notDrawn) + " not drawn";
		if (!worker_->pipelineRunning()) right += " (no pipeline)";
	}
	if (GetStatusBar()->GetStatusText(1) != right) SetStatusText(right, 1);
}

void ViewerFrame::writeState()
{
	if (opt_.stateFile.empty() || !shown_) return;
	const auto st = worker_->state();
	Json j;
	j["frame"] = shown_->frame;
	j["frame_count"] = shown_->frameCount;
	j["counter"] = frameLabel_->GetLabel().Trim().Trim(false).ToStdString();
	j["slider"] = slider_->GetValue();
	j["status"] = GetStatusBar()->GetStatusText(0).ToStdString();
	j["status_replay"] = GetStatusBar()->GetStatusText(1).ToStdString();
	j["playing"] = st.playing;
	j["mode"] = viewer::toString(st.mode);
	j["processed"] = st.processed;
	j["not_drawn"] = st.notDrawn;
	j["window"] = screenRect(this);
	j["view3d"] = screenRect(canvas_);
	j["slider_rect"] = screenRect(slider_);
	Json panels = Json::array();
	for (const auto* p : panels_) panels.push_back(screenRect(p));
	j["panels"] = panels;
	// written when it changes (a draw, a resize, the replay's counts)
	std::string text = jsonText(j);
	if (text == stateWritten_) return;
	try
	{
		writeJsonFile(opt_.stateFile, j);
		stateWritten_ = std::move(text);
	}
	catch (const std::exception& e)
	{
		std::cerr << "bims-viewer: warning: " << e.what() << "\n";
		opt_.stateFile.clear();  // said once
	}
}

void ViewerFrame::onTimer(wxTimerEvent&)
{
	placeSash();
	if (!worker_) return;
	// Tell the worker what was drawn (with a PNG sequence: once written).
	if (ackPending_ && (pngDir_.empty() || canvas_->captureDone()))
	{
		worker_->drawn(ackPending_);
		ackPending_ = 0;
	}
	const std::string err = worker_->takeError();
	if (!err.empty())
	{
		if (!opt_.screenshot.empty())
		{
			std::cerr << "bims-viewer: error: " << err << "\n";
			exitCode = 1;
			Close(true);
			return;
		}
		showError(err);
	}
	const auto v = worker_->latest();
	if (v && v != shown_ && !ackPending_) draw(v);
	updateControls();
	writeState();
	if (!opt_.screenshot.empty()) batchScreenshot();
}

void ViewerFrame::onPlayPause(wxCommandEvent&)
{
	if (worker_) worker_->togglePlay();
}

void ViewerFrame::onStep(wxCommandEvent&)
{
	if (worker_) worker_->step();
}

void ViewerFrame::onRestart(wxCommandEvent&)
{
	if (worker_) worker_->restart();
}

void ViewerFrame::onSliderReleased()
{
	sliderHeld_ = false;
	if (worker_) worker_->seek(static_cast<size_t>(slider_->GetValue()));
}

void ViewerFrame::onSpeed(wxCommandEvent&)
{
	if (worker_) worker_->setSpeed(kSpeeds[speedChoice_->GetSelection()]);
}

void ViewerFrame::onOpen(wxCommandEvent&)
{
	wxFileDialog dlg(this, "Open rawlog", "", "",
	                 "Rawlogs (*.rawlog)|*.rawlog|All files|*",
	                 wxFD_OPEN | wxFD_FILE_MUST_EXIST);
	if (dlg.ShowModal() != wxID_OK) return;
	auto vo = opt_.viewer;
	vo.rawlog = dlg.GetPath().ToStdString();
	vo.resultsDir.clear();
	vo.groundTruth.clear();
	vo.runPipeline = true;
	try
	{
		open(vo);
		worker_->play(true);
	}
	catch (const std::exception& e)
	{
		showError(e.what());
	}
}

void ViewerFrame::onOpenResults(wxCommandEvent&)
{
	if (!worker_)
	{
		showError("open a rawlog first");
		return;
	}
	wxDirDialog dlg(this, "bims-run output folder");
	if (dlg.ShowModal() != wxID_OK) return;
	auto vo = opt_.viewer;
	vo.resultsDir = dlg.GetPath().ToStdString();
	vo.runPipeline = false;
	try
	{
		open(vo);
		worker_->seek(0);
	}
	catch (const std::exception& e)
	{
		showError(e.what());
	}
}

void ViewerFrame::onScreenshot(wxCommandEvent&)
{
	wxFileDialog dlg(this, "Export screenshot of the 3D view", "",
	                 "bims-view.png", "PNG (*.png)|*.png",
	                 wxFD_SAVE | wxFD_OVERWRITE_PROMPT);
	if (dlg.ShowModal() != wxID_OK) return;
	canvas_->requestCapture(dlg.GetPath().ToStdString());
	canvas_->Refresh(false);
	canvas_->Update();
}

void ViewerFrame::onPngSequence(wxCommandEvent& ev)
{
	if (!ev.IsChecked())
	{
		pngDir_.clear();
		return;
	}
	wxDirDialog dlg(this, "Folder for the PNG sequence (NNNNNN.png)");
	if (dlg.ShowModal() != wxID_OK)
	{
		GetMenuBar()->Check(ID_PNG_SEQ, false);
		return;
	}
	pngDir_ = dlg.GetPath().ToStdString();
	// every frame must be drawn to be written
	GetMenuBar()->Check(ID_MODE_EVERY, true);
	opt_.mode = viewer::PlayMode::EveryFrame;
	if (worker_) worker_->setMode(opt_.mode);
}

void ViewerFrame::onLayer(wxCommandEvent& ev)
{
	opt_.layers.on[size_t(ev.GetId() - ID_LAYER_FIRST)] = ev.IsChecked();
	showLayers();  // hiding is at once; a layer shown comes with the next view
	canvas_->Refresh(false);
	if (worker_) worker_->setLayers(opt_.layers);
}

void ViewerFrame::onAbout(wxCommandEvent&)
{
	wxAboutDialogInfo info;
	info.SetName("bims-viewer");
	info.SetDescription(
	    "Replay of RGB-D + IMU rawlogs with Bayesian independent motion "
	    "segmentation (Lobo et al., MFI 2012).\nMoving points and tier 2: "
	    "red; tier 1 background subtraction: yellow; tier 0 occupancy: faint "
	    "blue (View menu).");
	wxAboutBox(info, this);
}

void ViewerFrame::batchScreenshot()
{
	// Once the window is shown and the target frame drawn: capture the next
	// render, then quit. (The time limit counts while the replay is idle:
	// reaching a far frame may take long.)
	if (worker_->waitIdle(0)) ++batchWaitTicks_;
	std::string err;
	if (!batchCaptureRequested_)
	{
		if (!IsShownOnScreen() || canvas_->GetClientSize().x < 10) return;
		if (!shown_ || shown_->frame != batchTarget_ || ackPending_ ||
		    worker_->latest() != shown_ || !worker_->waitIdle(0))
			return;
		canvas_->requestCapture(opt_.screenshot);
		canvas_->Refresh(false);
		canvas_->Update();
		batchCaptureRequested_ = true;
	}
	else if (canvas_->captureDone(&err))
	{
		opt_.screenshot.clear();  // done: the timer stops calling
		if (!err.empty())
		{
			std::cerr << "bims-viewer: error: " << err << "\n";
			exitCode = 1;
		}
		else
			std::cout << "bims-viewer: wrote " << canvas_->capturePath()
			          << std::endl;
		if (!opt_.keepOpen || !err.empty()) Close(true);
		return;
	}
	if (batchWaitTicks_ > 50 * 120)  // 2 min at 20 ms
	{
		opt_.screenshot.clear();
		std::cerr << "bims-viewer: error: the 3D view was never drawn (no "
		             "OpenGL on this display?)\n";
		exitCode = 1;
		Close(true);
	}
}

void ViewerFrame::showError(const std::string& what)
{
	std::cerr << "bims-viewer: error: " << what << "\n";
	wxMessageBox(what, "bims-viewer", wxOK | wxICON_ERROR, this);
}

}  // namespace bims::viewer_app
