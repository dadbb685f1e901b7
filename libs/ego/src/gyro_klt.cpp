#include <bims/ego/gyro_klt.h>

#include <opencv2/features2d.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/video/tracking.hpp>

#include <algorithm>
#include <cmath>
#include <numeric>
#include <stdexcept>

namespace bims::ego
{
cv::Mat dilateMask(const cv::Mat& mask, int px)
{
	CV_Assert(mask.type() == CV_8UC1 && px >= 0);
	cv::Mat out(mask.size(), CV_8UC1, cv::Scalar(0));
	// Nothing outside the non-zero pixels' box grown by px can be set; inside
	// it, cv::dilate of the ROI sees the (zero) pixels around it as the whole
	// image's dilation does.
	const cv::Rect box = cv::boundingRect(mask);
	if (box.empty()) return out;
	const cv::Rect roi = cv::Rect(box.x - px, box.y - px, box.width + 2 * px,
	                              box.height + 2 * px) &
	                     cv::Rect(0, 0, mask.cols, mask.rows);
	cv::Mat dst = out(roi);
	cv::dilate(mask(roi), dst,
	           cv::getStructuringElement(cv::MORPH_ELLIPSE,
	                                     cv::Size(2 * px + 1, 2 * px + 1)));
	return out;
}

GyroAidedKLT::GyroAidedKLT(const TrackerParams& p) : p_(p)
{
}

void GyroAidedKLT::reset()
{
	prevPyr_.clear();
	pts_.clear();
	ids_.clear();
	ages_.clear();
	tracks_.clear();
}

Eigen::Matrix3d GyroAidedKLT::infiniteHomography(
    const Eigen::Matrix3d& K, const Eigen::Matrix3d& R_CprevC)
{
	return K * R_CprevC.transpose() * K.inverse();
}

cv::Point2f GyroAidedKLT::warp(const Eigen::Matrix3d& H, const cv::Point2f& x)
{
	const Eigen::Vector3d y = H * Eigen::Vector3d(x.x, x.y, 1.0);
	return {static_cast<float>(y.x() / y.z()),
	        static_cast<float>(y.y() / y.z())};
}

const std::vector<Track>& GyroAidedKLT::track(const cv::Mat& grey,
                                              const Eigen::Matrix3d& K,
                                              const Eigen::Matrix3d* R_CprevC,
                                              const cv::Mat* movingMaskPrev)
{
	const cv::Mat* mask = checkedMask(grey, movingMaskPrev);
	stats_ = {};
	tracks_.clear();
	tried_.clear();
	std::vector<cv::Mat> pyr;
	cv::buildOpticalFlowPyramid(grey, pyr, cv::Size(p_.window, p_.window),
	                            p_.pyramid_levels, true);
	if (!prevPyr_.empty() && !pts_.empty())
	{
		std::vector<int> idx;
		tried_ = featuresOffMask(mask, grey.size(), idx);
		stats_.attempted = static_cast<int>(tried_.size());
		follow(pyr, grey.size(), K, R_CprevC, idx);
		stats_.tracked = static_cast<int>(tracks_.size());
	}
	else
		pts_.clear(), ids_.clear(), ages_.clear();
	size_ = grey.size();
	replenish(grey, mask);
	prevPyr_.swap(pyr);
	return tracks_;
}

const cv::Mat* GyroAidedKLT::checkedMask(const cv::Mat& grey,
                                         const cv::Mat* movingMaskPrev) const
{
	if (grey.empty() || grey.type() != CV_8UC1)
		throw std::invalid_argument(
		    "GyroAidedKLT::track: expected a non-empty 8-bit grey image");
	if (!prevPyr_.empty() && grey.size() != size_)
		throw std::invalid_argument(
		    "GyroAidedKLT::track: image size changed between frames");
	if (!movingMaskPrev || movingMaskPrev->empty()) return nullptr;
	if (movingMaskPrev->size() != grey.size() ||
	    movingMaskPrev->type() != CV_8UC1)
		throw std::invalid_argument(
		    "GyroAidedKLT::track: moving mask must be CV_8UC1 of the "
		    "image size");
	return movingMaskPrev;
}

std::vector<cv::Point2f> GyroAidedKLT::featuresOffMask(const cv::Mat* mask,
                                                       cv::Size size,
                                                       std::vector<int>& idx)
{
	// Drop features standing on regions labelled moving.
	std::vector<cv::Point2f> p0;
	for (size_t i = 0; i < pts_.size(); i++)
	{
		const cv::Point pi(cvRound(pts_[i].x), cvRound(pts_[i].y));
		if (mask && mask->at<uint8_t>(std::clamp(pi.y, 0, size.height - 1),
		                              std::clamp(pi.x, 0, size.width - 1)))
		{
			++stats_.droppedMask;
			continue;
		}
		p0.push_back(pts_[i]);
		idx.push_back(static_cast<int>(i));
	}
	return p0;
}

void GyroAidedKLT::follow(const std::vector<cv::Mat>& pyr, cv::Size size,
                          const Eigen::Matrix3d& K,
                          const Eigen::Matrix3d* R_CprevC,
                          const std::vector<int>& idx)
{
	const std::vector<cv::Point2f>& p0 = tried_;
	if (p0.empty())
	{
		pts_.clear(), ids_.clear(), ages_.clear();
		return;
	}
	// Lucas-Kanade from the gyro's prediction, and back (forward-backward
	// check)
	std::vector<cv::Point2f> p1(p0.size());
	int flags = 0;
	if (R_CprevC)
	{
		const Eigen::Matrix3d H = infiniteHomography(K, *R_CprevC);
		for (size_t i = 0; i < p0.size(); i++) p1[i] = warp(H, p0[i]);
		flags = cv::OPTFLOW_USE_INITIAL_FLOW;
	}
	const std::vector<cv::Point2f> guess =
	    R_CprevC ? p1 : p0;  // what LK started from
	std::vector<uint8_t> st, stBack;
	std::vector<float> err;
	const cv::Size win(p_.window, p_.window);
	const cv::TermCriteria term(cv::TermCriteria::COUNT | cv::TermCriteria::EPS,
	                            p_.max_iterations, p_.epsilon);
	cv::calcOpticalFlowPyrLK(prevPyr_, pyr, p0, p1, st, err, win,
	                         p_.pyramid_levels, term, flags, 1e-4);
	std::vector<cv::Point2f> back = p0;
	cv::calcOpticalFlowPyrLK(pyr, prevPyr_, p1, back, stBack, err, win,
	                         p_.pyramid_levels, term,
	                         cv::OPTFLOW_USE_INITIAL_FLOW, 1e-4);
	std::vector<cv::Point2f> keepPts;
	std::vector<int> keepIds, keepAges;
	const float b = static_cast<float>(p_.border_px);
	for (size_t i = 0; i < p0.size(); i++)
	{
		if (!st[i] || !stBack[i]) continue;
		const cv::Point2f& q = p1[i];
		if (q.x < b || q.y < b || q.x > size.width - 1 - b ||
		    q.y > size.height - 1 - b)
			continue;
		const cv::Point2f d = back[i] - p0[i];
		if (std::hypot(d.x, d.y) > p_.fb_threshold_px)
		{
			++stats_.lostFb;
			continue;
		}
		const int k = idx[i];
		Track t;
		t.id = ids_[k];
		t.age = ages_[k] + 1;
		t.prev = p0[i];
		t.cur = q;
		t.predicted = guess[i];
		tracks_.push_back(t);
		keepPts.push_back(q);
		keepIds.push_back(t.id);
		keepAges.push_back(t.age);
	}
	pts_.swap(keepPts);
	ids_.swap(keepIds);
	ages_.swap(keepAges);
}

void GyroAidedKLT::replenish(const cv::Mat& grey, const cv::Mat* movingMask)
{
	const int need = p_.max_features - static_cast<int>(pts_.size());
	if (need <= 0) return;
	// Where new features may appear: inside the border, outside the moving
	// regions and away from existing features.
	cv::Mat allow(grey.size(), CV_8UC1, cv::Scalar(0));
	const int b = static_cast<int>(std::ceil(p_.border_px)) + 1;
	if (grey.cols > 2 * b && grey.rows > 2 * b)
		allow(cv::Rect(b, b, grey.cols - 2 * b, grey.rows - 2 * b)).setTo(255);
	if (movingMask)
		allow.setTo(0, p_.mask_dilate_px > 0
		                   ? dilateMask(*movingMask, p_.mask_dilate_px)
		                   : *movingMask);
	const int r = static_cast<int>(std::lround(p_.min_distance_px));
	for (const auto& q : pts_)
		cv::circle(allow, q, r, cv::Scalar(0), cv::FILLED);

	std::vector<cv::KeyPoint> kps;
	if (p_.detector == FeatureDetector::Fast)
		cv::FAST(grey, kps, p_.fast_threshold, true);
	else
	{
		std::vector<cv::Point2f> corners;
		cv::goodFeaturesToTrack(grey, corners, 4 * p_.max_features,
		                        p_.gftt_quality, p_.min_distance_px, allow);
		for (size_t i = 0; i < corners.size(); i++)
			kps.emplace_back(corners[i], 1.f, -1.f,
			                 static_cast<float>(corners.size() - i));
	}
	std::sort(kps.begin(), kps.end(),
	          [](const auto& a, const auto& c)
	          { return a.response > c.response; });

	const int nCells = p_.grid_cols * p_.grid_rows;
	const int quota = (p_.max_features + nCells - 1) / nCells;
	std::vector<int> count(nCells, 0);
	const auto cellOf = [&](const cv::Point2f& q)
	{
		const int cx =
		    std::clamp(static_cast<int>(q.x * p_.grid_cols / grey.cols), 0,
		               p_.grid_cols - 1);
		const int cy =
		    std::clamp(static_cast<int>(q.y * p_.grid_rows / grey.rows), 0,
		               p_.grid_rows - 1);
		return cy * p_.grid_cols + cx;
	};
	for (const auto& q : pts_) ++count[cellOf(q)];
	int added = 0;
	for (const auto& kp : kps)
	{
		if (added >= need) break;
		const cv::Point pi(cvRound(kp.pt.x), cvRound(kp.pt.y));
		if (pi.x < 0 || pi.y < 0 || pi.x >= grey.cols || pi.y >= grey.rows)
			continue;
		if (!allow.at<uint8_t>(pi)) continue;
		const int c = cellOf(kp.pt);
		if (count[c] >= quota) continue;
		++count[c];
		++added;
		pts_.push_back(kp.pt);
		ids_.push_back(nextId_++);
		ages_.push_back(0);
		cv::circle(allow, kp.pt, r, cv::Scalar(0), cv::FILLED);
	}
	stats_.detected = added;
}

}  // namespace bims::ego
