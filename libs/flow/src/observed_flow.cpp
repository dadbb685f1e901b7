#include <bims/flow/observed_flow.h>
#include <opencv2/imgproc.hpp>

#include <limits>
#include <stdexcept>

namespace bims::flow
{
ObservedFlow::ObservedFlow(const FlowParams& p) : p_(p)
{
	if (p_.method == "dis")
	{
		int preset = cv::DISOpticalFlow::PRESET_FAST;
		if (p_.dis_preset == "ultrafast")
			preset = cv::DISOpticalFlow::PRESET_ULTRAFAST;
		if (p_.dis_preset == "medium")
			preset = cv::DISOpticalFlow::PRESET_MEDIUM;
		dis_ = cv::DISOpticalFlow::create(preset);
	}
	else if (p_.method != "farneback")
		throw std::invalid_argument("observed flow: unknown method '" +
		                            p_.method + "'");
	if (p_.downscale < 1)
		throw std::invalid_argument("observed flow: downscale must be >= 1");
}

cv::Mat ObservedFlow::compute(const cv::Mat& prev, const cv::Mat& cur)
{
	if (prev.empty() || cur.empty() || prev.size() != cur.size() ||
	    prev.type() != CV_8UC1 || cur.type() != CV_8UC1)
		throw std::invalid_argument(
		    "observed flow: need two non-empty CV_8UC1 images of one size");
	tensor_.release();
	if (p_.visible_change_grey > 0 || p_.refine_pose != "none")
		tensor_ = structureTensor(cur, p_.texture_window_px);
	cv::Mat a = cur, b = prev;
	if (p_.downscale > 1)
	{
		const cv::Size s(cur.cols / p_.downscale, cur.rows / p_.downscale);
		cv::resize(cur, a, s, 0, 0, cv::INTER_AREA);
		cv::resize(prev, b, s, 0, 0, cv::INTER_AREA);
	}
	cv::Mat flow;
	if (dis_)
		dis_->calc(a, b, flow);
	else
		cv::calcOpticalFlowFarneback(a, b, flow, 0.5, 4, 15, 3, 5, 1.1, 0);
	if (p_.downscale > 1)
	{
		cv::Mat up;
		cv::resize(flow, up, cur.size(), 0, 0, cv::INTER_LINEAR);
		up *= static_cast<double>(p_.downscale);
		flow = up;
	}
	return flow;
}

cv::Mat ObservedFlow::computeDerotated(const cv::Mat& prev, const cv::Mat& cur,
                                       const cv::Matx33d& H)
{
	if (prev.empty() || prev.size() != cur.size())
		throw std::invalid_argument(
		    "observed flow: need two non-empty CV_8UC1 images of one size");
	cv::Mat warped;
	// dst(u) = prev(H u)
	cv::warpPerspective(prev, warped, H, prev.size(),
	                    cv::INTER_LINEAR | cv::WARP_INVERSE_MAP,
	                    cv::BORDER_REPLICATE);
	cv::Mat flow = compute(warped, cur);
	composeWithHomography(flow, H, flow);
	return flow;
}

void composeWithHomography(const cv::Mat& residual, const cv::Matx33d& H,
                           cv::Mat& flow)
{
	if (residual.type() != CV_32FC2)
		throw std::invalid_argument(
		    "composeWithHomography: the residual must be CV_32FC2");
	flow.create(residual.size(), CV_32FC2);
	for (int v = 0; v < flow.rows; v++)
	{
		const auto* r = residual.ptr<cv::Vec2f>(v);
		auto* f = flow.ptr<cv::Vec2f>(v);
		for (int u = 0; u < flow.cols; u++)
		{
			const double x = u + r[u][0], y = v + r[u][1];
			const double X = H(0, 0) * x + H(0, 1) * y + H(0, 2);
			const double Y = H(1, 0) * x + H(1, 1) * y + H(1, 2);
			const double Z = H(2, 0) * x + H(2, 1) * y + H(2, 2);
			if (!(Z > 1e-12))
			{
				f[u] = {std::numeric_limits<float>::quiet_NaN(),
				        std::numeric_limits<float>::quiet_NaN()};
				continue;
			}
			f[u] = {static_cast<float>(X / Z - u),
			        static_cast<float>(Y / Z - v)};
		}
	}
}

cv::Mat structureTensor(const cv::Mat& grey, int window)
{
	if (grey.empty() || grey.type() != CV_8UC1)
		throw std::invalid_argument("structureTensor: need a CV_8UC1 image");
	if (window < 1)
		throw std::invalid_argument("structureTensor: window must be >= 1");
	cv::Mat gx, gy;
	// Sobel 3x3 sums 8x the gradient: scale to grey levels per pixel.
	cv::Sobel(grey, gx, CV_32F, 1, 0, 3, 1.0 / 8);
	cv::Sobel(grey, gy, CV_32F, 0, 1, 3, 1.0 / 8);
	cv::Mat prods[3] = {gx.mul(gx), gx.mul(gy), gy.mul(gy)};
	for (auto& m : prods)
		cv::boxFilter(m, m, CV_32F, {window, window}, {-1, -1}, true,
		              cv::BORDER_REFLECT);
	cv::Mat out;
	cv::merge(prods, 3, out);
	return out;
}

}  // namespace bims::flow
