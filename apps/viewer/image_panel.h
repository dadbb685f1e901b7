// A panel that shows one image scaled to fit, with a caption.
#pragma once

#include <wx/wx.h>

#include <opencv2/core.hpp>

namespace bims::viewer_app
{
class ImagePanel : public wxPanel
{
 public:
	ImagePanel(wxWindow* parent, const wxString& caption);
	/** Shows a BGR (CV_8UC3) image; empty = blank. */
	void setImage(const cv::Mat& bgr);

 private:
	void onPaint(wxPaintEvent&);
	wxString caption_;
	wxImage image_;
};

}  // namespace bims::viewer_app
