#include "image_panel.h"

#include <wx/dcbuffer.h>

#include <opencv2/imgproc.hpp>

namespace bims::viewer_app
{
ImagePanel::ImagePanel(wxWindow* parent, const wxString& caption)
    : wxPanel(parent, wxID_ANY), caption_(caption)
{
	SetBackgroundStyle(wxBG_STYLE_PAINT);
	SetMinSize(wxSize(160, 120));
	Bind(wxEVT_PAINT, &ImagePanel::onPaint, this);
	Bind(wxEVT_SIZE,
	     [this](wxSizeEvent& e)
	     {
		     Refresh();
		     e.Skip();
	     });
}

void ImagePanel::setImage(const cv::Mat& bgr)
{
	if (bgr.empty())
		image_ = wxImage();
	else
	{
		cv::Mat rgb;
		cv::cvtColor(bgr, rgb, cv::COLOR_BGR2RGB);
		image_ = wxImage(rgb.cols, rgb.rows);
		std::copy(rgb.data, rgb.data + rgb.total() * 3, image_.GetData());
	}
	Refresh(false);
}

void ImagePanel::onPaint(wxPaintEvent&)
{
	wxAutoBufferedPaintDC dc(this);
	dc.SetBackground(wxBrush(wxColour(40, 40, 40)));
	dc.Clear();
	const wxSize sz = GetClientSize();
	if (image_.IsOk() && sz.x > 4 && sz.y > 20)
	{
		const double s = std::min(double(sz.x) / image_.GetWidth(),
		                          double(sz.y - 16) / image_.GetHeight());
		const int w = std::max(1, int(image_.GetWidth() * s));
		const int h = std::max(1, int(image_.GetHeight() * s));
		const wxBitmap bmp(image_.Scale(w, h, wxIMAGE_QUALITY_NORMAL));
		dc.DrawBitmap(bmp, (sz.x - w) / 2, 16 + (sz.y - 16 - h) / 2);
	}
	dc.SetTextForeground(*wxWHITE);
	dc.DrawText(caption_, 4, 0);
}

}  // namespace bims::viewer_app
