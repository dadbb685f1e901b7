#include "scene_canvas.h"

#include <GL/gl.h>
#include <bims/io/output_paths.h>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <stdexcept>

namespace bims::viewer_app
{
SceneCanvas::SceneCanvas(wxWindow* parent)
    : mrpt::gui::CWxGLCanvasBase(parent, wxID_ANY, wxDefaultPosition,
                                 wxDefaultSize)
{
}

void SceneCanvas::requestCapture(const std::string& path)
{
	capturePath_ = path;
	captureError_.clear();
	captureDone_ = false;
}

bool SceneCanvas::captureDone(std::string* error) const
{
	if (error) *error = captureError_;
	return captureDone_;
}

void SceneCanvas::postRender()
{
	mrpt::gui::CWxGLCanvasBase::postRender();
	if (captureDone_) return;
	// Read the back buffer now: after the swap its content is undefined
	// (and the front buffer reads black under Mesa/Xvfb, MRPT_NOTES §7).
	GLint vp[4];
	glGetIntegerv(GL_VIEWPORT, vp);
	const int w = vp[2], h = vp[3];
	captureDone_ = true;
	if (w <= 0 || h <= 0)
	{
		captureError_ = "the 3D view has no size";
		return;
	}
	cv::Mat rgb(h, w, CV_8UC3);
	glReadBuffer(GL_BACK);
	glPixelStorei(GL_PACK_ALIGNMENT, 1);
	glReadPixels(0, 0, w, h, GL_RGB, GL_UNSIGNED_BYTE, rgb.data);
	cv::Mat bgr;
	cv::cvtColor(rgb, bgr, cv::COLOR_RGB2BGR);
	cv::flip(bgr, bgr, 0);  // GL rows go bottom-up
	try
	{
		bims::writeImageFile(capturePath_, bgr);
	}
	catch (const std::exception& e)
	{
		captureError_ = e.what();
	}
}

}  // namespace bims::viewer_app
