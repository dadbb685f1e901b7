#include <bims/common/clock.h>
#include <bims/common/so3.h>
#include <bims/ego/keyframe_anchor.h>

#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>

namespace bims::ego
{
namespace
{
constexpr double kDeg = M_PI / 180;
}  // namespace

KeyframeAnchor::KeyframeAnchor(const AnchorParams& p) : p_(p)
{
}

void KeyframeAnchor::clear()
{
	kf_.clear();
	pending_ = false;
}

KeyframeAnchor::Keyframe* KeyframeAnchor::nearest(
    const Eigen::Matrix3d& R_WC, const Eigen::Vector3d& t_WC,
    const std::vector<Keyframe*>& skip)
{
	Keyframe* best = nullptr;
	double bestScore = 1e300;
	// newest first: ties go to the most recent keyframe
	for (auto it = kf_.rbegin(); it != kf_.rend(); ++it)
	{
		if (std::find(skip.begin(), skip.end(), &*it) != skip.end()) continue;
		const double d = (it->t_WK - t_WC).norm() / p_.keyframe_distance_m;
		const double a = angleSO3(it->R_WK.transpose() * R_WC) /
		                 (p_.keyframe_angle_deg * kDeg);
		const double s = d * d + a * a;
		if (s < bestScore)
		{
			bestScore = s;
			best = &*it;
		}
	}
	return best;
}

AnchorResult KeyframeAnchor::track(
    const RgbdFrame& f, const Eigen::Matrix3d& R_pred,
    const Eigen::Vector3d& t_pred, const std::vector<InitialGuess>& others,
    const Eigen::Matrix3d* R_prior, const cv::Mat& moving,
    const TranslationPrior* tPrior, const AnchorGate* gate)
{
	const auto t0 = std::chrono::steady_clock::now();
	AnchorResult r;
	r.R_WC = R_pred;
	r.t_WC = t_pred;
	lastOutliers_.release();
	lastConsistent_.release();
	pending_ = false;
	// (also the frame that may become a keyframe: no copy of the images)
	cur_.build(f.grey, f.depth, f.K, p_, moving);
	haveLast_ = true;
	Keyframe* k = nearest(R_pred, t_pred);
	if (!k)
	{
		r.why = "no keyframe yet";
		return r;
	}
	Attempt best =
	    alignTo(*k, R_pred, t_pred, others, R_prior, r, tPrior, gate);
	// The nearest keyframe may be an old one the pose has drifted from (a
	// correction too large to take): the newest keyframe then anchors it.
	// Or it may hold too little static scene (made while a mover filled the
	// view): the next nearest ones then, up to kMoreKeyframes of them. Such
	// a keyframe may also accept the frame on a small share of it (less
	// than keyframe_min_overlap of its points inliers: the mover dropped
	// from it counts as covered, so no new keyframe comes while the static
	// scene behind the mover is revealed, and what its mask missed of the
	// mover, near and moving, pulls the pose); the others are then tried
	// too, and the one that finds the most inliers anchors the frame.
	const auto weak = [this](const AnchorResult& a)
	{ return !a.accepted || a.overlap < p_.keyframe_min_overlap; };
	constexpr size_t kMoreKeyframes = 3;
	std::vector<Keyframe*> tried = {k};
	for (size_t n = 0; weak(best.r) && n <= kMoreKeyframes; n++)
	{
		Keyframe* q = n == 0 ? &kf_.back() : nearest(R_pred, t_pred, tried);
		if (!q || std::find(tried.begin(), tried.end(), q) != tried.end())
			continue;
		tried.push_back(q);
		Attempt again =
		    alignTo(*q, R_pred, t_pred, others, R_prior, best.r, tPrior, gate);
		if (again.r.accepted &&
		    (!best.r.accepted || again.r.inliers > best.r.inliers))
			best = std::move(again);
	}
	// The mask may have left too little to align (or be wrong): once more
	// with every pixel, flagged (the feedback must not starve the tracker).
	if (!best.r.accepted && !moving.empty())
	{
		for (DenseLevel& L : cur_.levels) L.exclude.release();
		Attempt again =
		    alignTo(*k, R_pred, t_pred, others, R_prior, best.r, tPrior, gate);
		if (again.r.accepted)
		{
			best = std::move(again);
			best.r.maskIgnored = true;
		}
	}
	take(best);
	best.r.ms = msSince(t0);
	return best.r;
}

void KeyframeAnchor::take(Attempt& a)
{
	if (!a.r.accepted) return;
	lastOutliers_ = a.r.outliers;
	lastConsistent_ = a.consistent;
	// what the keyframe held there has moved away: not static
	if (a.seenThrough.empty()) return;
	const DenseLevel& L =
	    a.k->frame.levels[static_cast<size_t>(p_.finest_level)];
	cv::Mat m = cv::Mat::zeros(L.depth.size(), CV_8UC1);
	for (int i : a.seenThrough) m.data[i] = 255;
	cv::dilate(m, m, cv::Mat());
	a.k->frame.dropReadings(m, p_);
}

namespace
{
/** The alignment against a keyframe at (R_WK, t_WK): the guesses and the
 * priors turned into its frame (T_KC = T_WK^-1 T_WC). */
DenseAlignResult alignInKeyframe(
    const DenseFrame& key, const Eigen::Matrix3d& R_WK,
    const Eigen::Vector3d& t_WK, const DenseFrame& cur,
    const std::vector<InitialGuess>& guesses, const Eigen::Matrix3d* R_prior,
    const TranslationPrior* tPrior, const AnchorParams& p)
{
	std::vector<InitialGuess> inits;
	for (const auto& g : guesses)
		inits.push_back(
		    {R_WK.transpose() * g.R, R_WK.transpose() * (g.t - t_WK)});
	Eigen::Matrix3d R_KCprior;
	if (R_prior) R_KCprior = R_WK.transpose() * *R_prior;
	// the translation prior in the keyframe's frame: t_KC = R_WK^T (t - t_WK)
	TranslationPrior tK;
	if (tPrior)
	{
		tK.t = R_WK.transpose() * (tPrior->t - t_WK);
		tK.info = R_WK.transpose() * tPrior->info * R_WK;
	}
	return alignDense(key, cur, inits, p, R_prior ? &R_KCprior : nullptr,
	                  p.rotation_prior_sigma_deg * kDeg,
	                  tPrior ? &tK : nullptr);
}

/** The correction of (R_WC, t_WC) against the nearest of the guesses: a
 * result next to the constant-velocity guess is no jump even when the
 * frame-to-frame one (that people in view can corrupt) is far. */
void nearestCorrection(const Eigen::Matrix3d& R_WC, const Eigen::Vector3d& t_WC,
                       const std::vector<InitialGuess>& guesses,
                       const AnchorParams& p, AnchorResult& r)
{
	r.correction_m = 1e300;
	r.correction_deg = 0;
	for (const auto& g : guesses)
	{
		const double dm = (t_WC - g.t).norm();
		const double dd = angleSO3(g.R.transpose() * R_WC) / kDeg;
		if (dm / p.max_correction_m + dd / p.max_correction_deg <
		    r.correction_m / p.max_correction_m +
		        r.correction_deg / p.max_correction_deg)
		{
			r.correction_m = dm;
			r.correction_deg = dd;
		}
	}
}

/** Why the alignment \a a is refused (r.why; empty: taken), and whether a
 * large correction is a relocalisation. */
void judge(const DenseAlignResult& a, const AnchorParams& p, AnchorResult& r)
{
	r.why.clear();
	r.accepted = false;
	r.relocalised = false;
	if (!a.ok)
		r.why = a.why;
	else if (r.correction_m > p.max_correction_m ||
	         r.correction_deg > p.max_correction_deg)
	{
		// A large correction is taken only from a keyframe the frame fits
		// almost entirely: the pose had drifted (flagged, not silent).
		if (a.inlier_fraction >= p.relocalise_inlier_fraction &&
		    a.overlap >= p.relocalise_overlap)
			r.relocalised = true;
		else
			r.why = "correction too large";
	}
}
}  // namespace

KeyframeAnchor::Attempt KeyframeAnchor::alignTo(
    Keyframe& k, const Eigen::Matrix3d& R_pred, const Eigen::Vector3d& t_pred,
    const std::vector<InitialGuess>& others, const Eigen::Matrix3d* R_prior,
    const AnchorResult& start, const TranslationPrior* tPrior,
    const AnchorGate* gate)
{
	Attempt out{start, &k, cv::Mat(), {}};
	AnchorResult& r = out.r;
	std::vector<InitialGuess> guesses = {{R_pred, t_pred}};
	guesses.insert(guesses.end(), others.begin(), others.end());
	const DenseAlignResult a = alignInKeyframe(k.frame, k.R_WK, k.t_WK, cur_,
	                                           guesses, R_prior, tPrior, p_);
	const double sigmaRot = p_.rotation_prior_sigma_deg * kDeg;
	const double rotationInfo = !R_prior ? 0.0
	                            : sigmaRot > 0
	                                ? 1 / (sigmaRot * sigmaRot)
	                                : std::numeric_limits<double>::infinity();
	r.position_information =
	    k.R_WK * translationInformation(a.information, rotationInfo) *
	    k.R_WK.transpose();
	r.tried = true;
	r.keyframe = k.id;
	r.points = a.points;
	r.inliers = a.inliers;
	r.inlier_fraction = a.inlier_fraction;
	r.overlap = a.overlap;
	r.coverage = a.coverage;
	r.guess = a.guess;
	r.outliers = a.outliers;
	out.consistent = a.consistent;
	const Eigen::Matrix3d R_WC = k.R_WK * a.R_RC;
	const Eigen::Vector3d t_WC = k.R_WK * a.t_RC + k.t_WK;
	nearestCorrection(R_WC, t_WC, guesses, p_, r);
	judge(a, p_, r);
	r.gated = false;
	if (r.why.empty() && gate && !(*gate)(t_WC, r.position_information))
	{
		r.gated = true;
		r.why = "inconsistent with the inertial prediction";
	}
	if (!r.why.empty()) return out;
	r.accepted = true;
	r.R_WC = R_WC;
	r.t_WC = t_WC;
	r.seen_through = static_cast<int>(a.seenThrough.size());
	out.seenThrough = a.seenThrough;
	return out;
}

bool KeyframeAnchor::wantKeyframe(const AnchorResult& r,
                                  const Eigen::Matrix3d& R_WC,
                                  const Eigen::Vector3d& t_WC, bool force)
{
	bool want = force || kf_.empty();
	if (!want && r.accepted)
	{
		for (const auto& k : kf_)
			if (k.id == r.keyframe)
				want = (k.t_WK - t_WC).norm() > p_.keyframe_distance_m ||
				       angleSO3(k.R_WK.transpose() * R_WC) >
				           p_.keyframe_angle_deg * kDeg;
		want = want || r.coverage < p_.keyframe_min_overlap;
	}
	pending_ = want && haveLast_;
	// outliers of an alignment that was not accepted say nothing
	if (!r.accepted)
	{
		lastOutliers_.release();
		lastConsistent_.release();
	}
	R_pending_ = R_WC;
	t_pending_ = t_WC;
	return pending_;
}

bool KeyframeAnchor::addPending(const cv::Mat& moving)
{
	if (!pending_) return false;
	pending_ = false;
	// what moved in it (its mask, its alignment outliers) is no keyframe
	// content
	const DenseLevel& Lf = cur_.levels[static_cast<size_t>(p_.finest_level)];
	cv::Mat drop = cv::Mat::zeros(Lf.depth.size(), CV_8UC1);
	if (!moving.empty())
	{
		cv::Mat m;
		cv::resize(moving, m, drop.size(), 0, 0, cv::INTER_AREA);  // any > 0
		drop.setTo(255, m);
	}
	// (and what was predicted moving when it was tracked)
	if (Lf.exclude.size() == drop.size()) drop.setTo(255, Lf.exclude);
	if (lastOutliers_.size() == drop.size())
	{
		cv::Mat o;
		cv::dilate(lastOutliers_, o, cv::Mat());
		drop.setTo(255, o);
	}
	Keyframe k;
	k.id = nextId_++;
	k.R_WK = R_pending_;
	k.t_WK = t_pending_;
	k.frame = std::move(cur_);
	k.frame.prepareReference(p_);
	k.frame.dropReadings(drop, p_);
	haveLast_ = false;
	kf_.push_back(std::move(k));
	while (static_cast<int>(kf_.size()) > p_.max_keyframes) kf_.pop_front();
	return true;
}

cv::Mat KeyframeAnchor::vetoMask(const cv::Mat& moving, double* vetoed) const
{
	if (vetoed) *vetoed = 0;
	const int level = p_.finest_level;
	// (the alignment's images are of the last tracked frame's finest
	// level: the mask must be of that frame's size)
	if (!(p_.mask_veto_consistent > 0) || moving.empty() ||
	    lastConsistent_.empty() || lastOutliers_.empty() ||
	    (moving.cols >> level) != lastConsistent_.cols ||
	    (moving.rows >> level) != lastConsistent_.rows)
		return moving;
	// per connected region of the mask: its pixels on the static surface
	// (consistent) and off it (outliers), at the alignment's level
	cv::Mat labels, stats, centroids;
	const int n = cv::connectedComponentsWithStats(moving, labels, stats,
	                                               centroids, 8, CV_32S);
	if (n <= 1) return moving;
	std::vector<int> on(n, 0), off(n, 0);
	const int W = lastConsistent_.cols, H = lastConsistent_.rows;
	for (int v = 0; v < labels.rows && (v >> level) < H; v++)
	{
		const int* l = labels.ptr<int>(v);
		const uint8_t* c = lastConsistent_.ptr<uint8_t>(v >> level);
		const uint8_t* o = lastOutliers_.ptr<uint8_t>(v >> level);
		for (int u = 0; u < labels.cols && (u >> level) < W; u++)
		{
			if (l[u] == 0) continue;
			if (c[u >> level])
				++on[l[u]];
			else if (o[u >> level])
				++off[l[u]];
		}
	}
	// the regions dropped, and the share of the mask's pixels they hold
	std::vector<uint8_t> drop(n, 0);
	long total = 0, dropped = 0;
	for (int k = 1; k < n; k++)
	{
		const int seen = on[k] + off[k];
		drop[k] = seen > 0 && on[k] >= p_.mask_veto_consistent * seen;
		const int area = stats.at<int>(k, cv::CC_STAT_AREA);
		total += area;
		dropped += drop[k] ? area : 0;
	}
	if (dropped == 0) return moving;
	cv::Mat kept = moving.clone();
	for (int v = 0; v < labels.rows; v++)
	{
		const int* l = labels.ptr<int>(v);
		uint8_t* m = kept.ptr<uint8_t>(v);
		for (int u = 0; u < labels.cols; u++)
			if (drop[l[u]]) m[u] = 0;
	}
	if (vetoed) *vetoed = double(dropped) / total;
	return kept;
}

}  // namespace bims::ego
