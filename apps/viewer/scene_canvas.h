// MRPT's wx GL canvas with one addition: it can copy what it just rendered
// (the back buffer, before the swap) into a PNG file.
#pragma once

// wx first, then MRPT's canvas (which includes wx/glcanvas.h).
#include <mrpt/gui/CWxGLCanvasBase.h>
#include <wx/wx.h>

#include <string>

namespace bims::viewer_app
{
class SceneCanvas : public mrpt::gui::CWxGLCanvasBase
{
 public:
	explicit SceneCanvas(wxWindow* parent);
	/** The next render also writes the canvas pixels to \a path (PNG). */
	void requestCapture(const std::string& path);
	/** True once the last requested capture was written; the error text
	 * (empty when fine) in \a error. */
	bool captureDone(std::string* error = nullptr) const;
	const std::string& capturePath() const { return capturePath_; }

 protected:
	void postRender() override;

 private:
	std::string capturePath_, captureError_;
	bool captureDone_ = true;
};

}  // namespace bims::viewer_app
