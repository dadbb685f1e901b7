#include "viewer_frame.h"
#include <bims/common/frame_files.h>

#include <bims/common/app.h>

#include <wx/aboutdlg.h>
#include <wx/dirdlg.h>
#include <wx/filedlg.h>
#include <wx/slider.h>
#include <wx/splitter.h>

#include <cstdio>
#include <iostream>

#include "image_panel.h"
#include "scene_canvas.h"

namespace bims::viewer_app
{
int ViewerFrame::exitCode = 0;

namespace
{
enum
{
	ID_OPEN_RESULTS = wxID_HIGHEST + 1,
	ID_SCREENSHOT,
	ID_PNG_SEQ,
	ID_LAYER_CLOUD,
	ID_LAYER_T0,
	ID_LAYER_T1,
	ID_LAYER_T2,
	ID_LAYER_EST,
	ID_LAYER_GT,
	ID_PLAY,
	ID_STEP,
	ID_RESTART,
	ID_SLIDER,
	ID_SPEED
};
const double kSpeeds[] = {0.1, 0.25, 0.5, 1, 2, 4, 8};
constexpr viewer::Panel kPanels[] = {
    viewer::Panel::RgbMask, viewer::Panel::Depth, viewer::Panel::FlowObserved,
    viewer::Panel::FlowExpected, viewer::Panel::Labels};
}  // namespace

ViewerFrame::ViewerFrame(const AppOptions& opt)
    : wxFrame(nullptr, wxID_ANY, "bims-viewer", wxDefaultPosition,
              wxSize(opt.width, opt.height)),
      opt_(opt),
      timer_(this),
      batchTimer_(this)
{
	buildMenus();
	buildLayout();
	CreateStatusBar();
	SetStatusText("File > Open rawlog... to start");
	Bind(wxEVT_TIMER, &ViewerFrame::onTimer, this, timer_.GetId());
	Bind(
	    wxEVT_TIMER, [this](wxTimerEvent&) { startBatchScreenshot(); },
	    batchTimer_.GetId());
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
	if (ctl_ && opt_.frames > 0)
	{
		ctl_->seek(static_cast<size_t>(opt_.frames - 1));
		refreshViews(true);
	}
	if (!opt_.screenshot.empty())
		batchTimer_.Start(100);  // capture once the window is drawn
	else if (ctl_)
	{
		ctl_->setSpeed(opt_.speed);
		// the speed box shows --speed when it is one of its entries
		for (size_t i = 0; i < std::size(kSpeeds); ++i)
			if (kSpeeds[i] == opt_.speed) speedChoice_->SetSelection(int(i));
		ctl_->setPlaying(!opt_.paused && opt_.frames <= 0);
		updateControls();
	}
	lastTick_ = std::chrono::steady_clock::now();
	timer_.Start(15);
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
	view->AppendCheckItem(ID_LAYER_CLOUD, "Registered &cloud")->Check(true);
	view->AppendCheckItem(ID_LAYER_T0, "Tier &0 occupied voxels (blue)")
	    ->Check(true);
	view->AppendCheckItem(ID_LAYER_T1, "Tier &1 moving voxels (yellow)")
	    ->Check(true);
	view->AppendCheckItem(ID_LAYER_T2, "Tier &2 moving voxels (red)")
	    ->Check(true);
	view->AppendCheckItem(ID_LAYER_EST, "&Estimated trajectory (cyan)")
	    ->Check(true);
	view->AppendCheckItem(ID_LAYER_GT, "&Ground truth (green)")->Check(true);
	auto* play = new wxMenu;
	// Plain keys (GTK accelerators need modifiers): see the char hook.
	play->Append(ID_PLAY, "&Play / Pause (Space)");
	play->Append(ID_STEP, "&Step one frame (Right)");
	play->Append(ID_RESTART, "&Restart (Home)");
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
	Bind(wxEVT_MENU, &ViewerFrame::onLayer, this, ID_LAYER_CLOUD, ID_LAYER_GT);
}

void ViewerFrame::buildLayout()
{
	auto* split = new wxSplitterWindow(this, wxID_ANY, wxDefaultPosition,
	                                   wxDefaultSize, wxSP_LIVE_UPDATE);
	canvas_ = new SceneCanvas(split);
	auto* right = new wxPanel(split);
	auto* grid = new wxGridSizer(3, 2, 2, 2);
	for (size_t i = 0; i < panels_.size(); ++i)
	{
		panels_[i] = new ImagePanel(right, viewer::toString(kPanels[i]));
		grid->Add(panels_[i], 1, wxEXPAND);
	}
	right->SetSizer(grid);
	split->SplitVertically(canvas_, right, opt_.width * 3 / 5);
	split->SetSashGravity(0.6);
	split->SetMinimumPaneSize(100);
	// The frame gets its real size only once shown, and under load the
	// window manager may resize it after the first events: the sash stays
	// at 3/5 of the width (placeSash) until the user drags it (a drag is
	// told by SASH_POS_CHANGING, sent only while the mouse moves the sash;
	// wx sends SASH_POS_CHANGED also when it moves the sash itself).
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

	// Timeline: play/pause, step, restart, speed, slider.
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
	// On release only: going back re-runs the pipeline from frame 0.
	slider_->Bind(wxEVT_SCROLL_CHANGED,
	              [this](wxScrollEvent&)
	              {
		              wxCommandEvent e;
		              onSlider(e);
	              });
}

void ViewerFrame::placeSash()
{
	const int want = GetClientSize().x * 3 / 5;
	if (!sashMovedByUser_ && split_->GetSashPosition() != want)
		split_->SetSashPosition(want);
}

void ViewerFrame::open(const viewer::ViewerOptions& vo)
{
	wxBusyCursor busy;
	auto ctl = std::make_unique<viewer::ReplayController>(vo);
	ctl_ = std::move(ctl);
	opt_.viewer = vo;
	SetTitle("bims-viewer - " + vo.rawlog);
	slider_->SetRange(0, std::max<int>(1, int(ctl_->frameCount()) - 1));
	auto* m = GetMenuBar();
	ctl_->layers().cloud = m->IsChecked(ID_LAYER_CLOUD);
	ctl_->layers().tier0 = m->IsChecked(ID_LAYER_T0);
	ctl_->layers().tier1 = m->IsChecked(ID_LAYER_T1);
	ctl_->layers().tier2 = m->IsChecked(ID_LAYER_T2);
	ctl_->layers().estimated = m->IsChecked(ID_LAYER_EST);
	ctl_->layers().groundTruth = m->IsChecked(ID_LAYER_GT);
	refreshViews(true);
}

void ViewerFrame::refreshViews(bool resetCamera)
{
	if (!ctl_) return;
	auto& scene = canvas_->getOpenGLSceneRef();
	ctl_->fillScene(*scene);
	if (resetCamera || ctl_->currentFrame() == 0)
	{
		const auto c = ctl_->suggestedCamera();
		canvas_->setCameraPointing(c.pointX, c.pointY, c.pointZ);
		canvas_->setZoomDistance(c.zoom);
		canvas_->setAzimuthDegrees(c.azimuthDeg);
		canvas_->setElevationDegrees(c.elevationDeg);
	}
	if (!pngDir_.empty() && ctl_->currentFrame() >= 0)
	{
		canvas_->requestCapture(pngDir_ + "/" +
		                        bims::frameFileName(ctl_->currentFrame()));
	}
	canvas_->Refresh(false);
	for (size_t i = 0; i < panels_.size(); ++i)
		panels_[i]->setImage(ctl_->panel(kPanels[i]));
	updateControls();
}

void ViewerFrame::updateControls()
{
	if (!ctl_) return;
	const long cur = ctl_->currentFrame();
	slider_->SetValue(std::max(0L, cur));
	frameLabel_->SetLabel(
	    wxString::Format("  %ld / %zu  ", cur, ctl_->frameCount() - 1));
	const wxString play = ctl_->playing() ? "Pause" : "Play";
	if (playBtn_->GetLabel() != play) playBtn_->SetLabel(play);
	SetStatusText(ctl_->statusText());
}

void ViewerFrame::onTimer(wxTimerEvent&)
{
	// While playing, the event loop may never go idle (the pipeline and the
	// software-rendered 3D view take longer than the timer's period), so
	// nothing queued with CallAfter runs: the sash is placed here too (it
	// was left 1095 px out of 1200, the image panels 50 px wide;
	// test_viewer_gui's PanelsKeepTheirWidthWhilePlaying).
	placeSash();
	const auto now = std::chrono::steady_clock::now();
	const double dt = std::chrono::duration<double>(now - lastTick_).count();
	lastTick_ = now;
	if (!ctl_ || !ctl_->playing()) return;
	// Exporting a PNG sequence: every frame must be drawn (and written)
	// before the next one; playback slows down to the drawing speed.
	if (!pngDir_.empty() && !canvas_->captureDone()) return;
	try
	{
		if (ctl_->advance(dt) > 0) refreshViews();
		if (!ctl_->playing()) updateControls();
	}
	catch (const std::exception& e)
	{
		ctl_->setPlaying(false);
		showError(e.what());
	}
}

void ViewerFrame::onPlayPause(wxCommandEvent&)
{
	if (!ctl_) return;
	ctl_->setPlaying(!ctl_->playing());
	lastTick_ = std::chrono::steady_clock::now();
	updateControls();
}

void ViewerFrame::onStep(wxCommandEvent&)
{
	if (!ctl_) return;
	ctl_->setPlaying(false);
	try
	{
		if (ctl_->step()) refreshViews();
	}
	catch (const std::exception& e)
	{
		showError(e.what());
	}
	updateControls();
}

void ViewerFrame::onRestart(wxCommandEvent&)
{
	if (!ctl_) return;
	ctl_->setPlaying(false);
	ctl_->seek(0);
	refreshViews(true);
}

void ViewerFrame::onSlider(wxCommandEvent&)
{
	if (!ctl_) return;
	wxBusyCursor busy;  // going back re-runs the pipeline from frame 0
	ctl_->setPlaying(false);
	try
	{
		ctl_->seek(static_cast<size_t>(slider_->GetValue()));
	}
	catch (const std::exception& e)
	{
		showError(e.what());
	}
	refreshViews();
}

void ViewerFrame::onSpeed(wxCommandEvent&)
{
	if (ctl_) ctl_->setSpeed(kSpeeds[speedChoice_->GetSelection()]);
	updateControls();
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
		ctl_->setPlaying(true);
		updateControls();
	}
	catch (const std::exception& e)
	{
		showError(e.what());
	}
}

void ViewerFrame::onOpenResults(wxCommandEvent&)
{
	if (!ctl_)
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
}

void ViewerFrame::onLayer(wxCommandEvent& ev)
{
	if (!ctl_) return;
	auto& l = ctl_->layers();
	const bool on = ev.IsChecked();
	switch (ev.GetId())
	{
		case ID_LAYER_CLOUD:
			l.cloud = on;
			break;
		case ID_LAYER_T0:
			l.tier0 = on;
			break;
		case ID_LAYER_T1:
			l.tier1 = on;
			break;
		case ID_LAYER_T2:
			l.tier2 = on;
			break;
		case ID_LAYER_EST:
			l.estimated = on;
			break;
		case ID_LAYER_GT:
			l.groundTruth = on;
			break;
	}
	refreshViews();
}

void ViewerFrame::onAbout(wxCommandEvent&)
{
	wxAboutDialogInfo info;
	info.SetName("bims-viewer");
	info.SetDescription(
	    "Replay of RGB-D + IMU rawlogs with Bayesian independent motion "
	    "segmentation (Lobo et al., MFI 2012).\nTier 0 occupancy: blue; "
	    "tier 1 background subtraction: yellow; tier 2 flow consistency: "
	    "red.");
	wxAboutBox(info, this);
}

void ViewerFrame::startBatchScreenshot()
{
	// Wait until the canvas has a size and has rendered once, then capture
	// the next render, then quit.
	++batchWaitTicks_;
	std::string err;
	if (!batchCaptureRequested_)
	{
		if (!IsShownOnScreen() || canvas_->GetClientSize().x < 10) return;
		refreshViews();
		canvas_->requestCapture(opt_.screenshot);
		canvas_->Refresh(false);
		batchCaptureRequested_ = true;
	}
	else if (canvas_->captureDone(&err))
	{
		batchTimer_.Stop();
		if (!err.empty())
		{
			std::cerr << "bims-viewer: error: " << err << "\n";
			exitCode = 1;
		}
		else
			std::cout << "bims-viewer: wrote " << opt_.screenshot << std::endl;
		if (!opt_.keepOpen || !err.empty()) Close(true);
		return;
	}
	if (batchWaitTicks_ > 300)  // 30 s
	{
		batchTimer_.Stop();
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
