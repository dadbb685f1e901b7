// The vectorised / buffered flow stages against their plain definitions,
// written here per pixel in double precision.
#include <bims/flow/consistency.h>
#include <bims/flow/expected_flow.h>
#include <bims/flow/flow_pose.h>
#include <bims/flow/observed_flow.h>
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>

#include "test_util.h"

using namespace bims::flow;
using mrpt::poses::CPose3D;

namespace
{
constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();
constexpr float kInf = std::numeric_limits<float>::infinity();

/** Largest end-point difference of two flows over the pixels whose
 * reference \a ref lands within a frame's size of the image (u + ref(u) in
 * [-W, 2W] x [-H, 2H]); both must be NaN at the same pixels, and where the
 * reference lands farther out, \a a must leave the image too (the labels
 * skip those): mismatches in \a nanMismatch. */
double maxFlowDiff(const cv::Mat& a, const cv::Mat& ref, int* nanMismatch)
{
	double m = 0;
	*nanMismatch = 0;
	const int W = ref.cols, H = ref.rows;
	for (int v = 0; v < H; v++)
		for (int u = 0; u < W; u++)
		{
			const auto x = a.at<cv::Vec2f>(v, u), y = ref.at<cv::Vec2f>(v, u);
			const bool nx = std::isnan(x[0]) || std::isnan(x[1]);
			const bool ny = std::isnan(y[0]) || std::isnan(y[1]);
			if (nx || ny)
			{
				*nanMismatch += nx != ny;
				continue;
			}
			const double yu = u + y[0], yv = v + y[1];
			if (!(yu >= -W && yu <= 2 * W && yv >= -H && yv <= 2 * H))
			{
				const double xu = u + x[0], xv = v + x[1];
				*nanMismatch +=
				    xu >= 0 && xu <= W - 1 && xv >= 0 && xv <= H - 1;
				continue;
			}
			m = std::max({m, std::abs(double(x[0]) - y[0]),
			              std::abs(double(x[1]) - y[1])});
		}
	return m;
}

cv::Mat randomFlow(int w, int h, float range, std::mt19937& rng)
{
	std::uniform_real_distribution<float> d(-range, range);
	cv::Mat f(h, w, CV_32FC2);
	for (int v = 0; v < h; v++)
		for (int u = 0; u < w; u++) f.at<cv::Vec2f>(v, u) = {d(rng), d(rng)};
	return f;
}

/** flow(u) = H (u + r(u)) - u in double, NaN where the third coordinate is
 * not positive. */
cv::Mat composeReference(const cv::Mat& r, const cv::Matx33d& H)
{
	cv::Mat f(r.size(), CV_32FC2);
	for (int v = 0; v < r.rows; v++)
		for (int u = 0; u < r.cols; u++)
		{
			const auto d = r.at<cv::Vec2f>(v, u);
			const cv::Vec3d p = H * cv::Vec3d(u + d[0], v + d[1], 1.0);
			f.at<cv::Vec2f>(v, u) =
			    p[2] > 1e-12
			        ? cv::Vec2f(float(p[0] / p[2] - u), float(p[1] / p[2] - v))
			        : cv::Vec2f(kNaN, kNaN);
		}
	return f;
}

/** Index reflected as BORDER_REFLECT_101 (gfedcb|abcdefgh|gfedcba). */
int reflect101(int i, int n)
{
	while (i < 0 || i >= n) i = i < 0 ? -i : 2 * n - 2 - i;
	return i;
}

/** Index reflected as BORDER_REFLECT (fedcba|abcdefgh|hgfedcb). */
int reflect(int i, int n)
{
	while (i < 0 || i >= n) i = i < 0 ? -i - 1 : 2 * n - 1 - i;
	return i;
}

/** The structure tensor by its definition: 3x3 Sobel gradients / 8 (border
 * reflected 101), window means of their products (border reflected). */
cv::Mat tensorReference(const cv::Mat& g, int window)
{
	const int W = g.cols, H = g.rows;
	cv::Mat gx(H, W, CV_64F), gy(H, W, CV_64F);
	auto I = [&](int v, int u)
	{ return double(g.at<uint8_t>(reflect101(v, H), reflect101(u, W))); };
	for (int v = 0; v < H; v++)
		for (int u = 0; u < W; u++)
		{
			gx.at<double>(v, u) =
			    (I(v - 1, u + 1) + 2 * I(v, u + 1) + I(v + 1, u + 1) -
			     I(v - 1, u - 1) - 2 * I(v, u - 1) - I(v + 1, u - 1)) /
			    8;
			gy.at<double>(v, u) =
			    (I(v + 1, u - 1) + 2 * I(v + 1, u) + I(v + 1, u + 1) -
			     I(v - 1, u - 1) - 2 * I(v - 1, u) - I(v - 1, u + 1)) /
			    8;
		}
	cv::Mat S(H, W, CV_32FC3);
	const int a = window / 2;
	for (int v = 0; v < H; v++)
		for (int u = 0; u < W; u++)
		{
			double s[3] = {0, 0, 0};
			for (int j = v - a; j < v - a + window; j++)
				for (int i = u - a; i < u - a + window; i++)
				{
					const double x =
					    gx.at<double>(reflect(j, H), reflect(i, W));
					const double y =
					    gy.at<double>(reflect(j, H), reflect(i, W));
					s[0] += x * x;
					s[1] += x * y;
					s[2] += y * y;
				}
			const double n = double(window) * window;
			S.at<cv::Vec3f>(v, u) = {float(s[0] / n), float(s[1] / n),
			                         float(s[2] / n)};
		}
	return S;
}

/** The largest difference of two tensors relative to the largest entry. */
double maxRelTensorDiff(const cv::Mat& a, const cv::Mat& b)
{
	double m = 0, scale = 1e-30;
	for (int v = 0; v < a.rows; v++)
		for (int u = 0; u < a.cols; u++)
			for (int c = 0; c < 3; c++)
			{
				const double x = a.at<cv::Vec3f>(v, u)[c],
				             y = b.at<cv::Vec3f>(v, u)[c];
				m = std::max(m, std::abs(x - y));
				scale = std::max(scale, std::abs(y));
			}
	return m / scale;
}
}  // namespace

TEST(ObservedFlow, CompositionEqualsThePerPixelFormula)
{
	std::mt19937 rng(5);
	std::uniform_real_distribution<double> ang(-0.2, 0.2), per(-2e-4, 2e-4);
	// odd width: the vector loop's scalar tail too
	for (const cv::Size s : {cv::Size(640, 480), cv::Size(163, 61)})
		for (int k = 0; k < 12; k++)
		{
			const auto cam = test::vgaCamera(s.width, s.height);
			cv::Matx33d H = rotationHomography(
			    cam, CPose3D(0, 0, 0, ang(rng), ang(rng), ang(rng)));
			// general homographies too (projective part): some with the
			// horizon inside the image, where the flow is NaN
			if (k % 3 == 1)
			{
				H(2, 0) += per(rng);
				H(2, 1) += per(rng);
			}
			if (k % 3 == 2) H(2, 0) += -1.0 / (0.6 * s.width);
			const cv::Mat r = randomFlow(s.width, s.height, 20, rng);
			const cv::Mat ref = composeReference(r, H);
			cv::Mat out;
			composeWithHomography(r, H, out);
			int nanMismatch = 0;
			EXPECT_LT(maxFlowDiff(out, ref, &nanMismatch), 1e-3) << k;
			EXPECT_EQ(nanMismatch, 0) << k;
			// in place
			cv::Mat inPlace = r.clone();
			composeWithHomography(inPlace, H, inPlace);
			EXPECT_EQ(cv::norm(inPlace, out, cv::NORM_INF), 0.0) << k;
		}
	cv::Mat bad(4, 4, CV_32FC1), out;
	EXPECT_THROW(composeWithHomography(bad, cv::Matx33d::eye(), out),
	             std::invalid_argument);
}

TEST(StructureTensor, EqualsThePlainDefinition)
{
	const cv::Mat g = test::texture(97, 53, 4);
	for (const int window : {1, 4, 9, 15, 47})  // 47: beyond the int32 path
	{
		const cv::Mat ref = tensorReference(g, window);
		const cv::Mat S = structureTensor(g, window);
		ASSERT_EQ(S.type(), CV_32FC3);
		EXPECT_LT(maxRelTensorDiff(S, ref), 1e-6) << window;
	}
	// the strongest gradients a grey image has (a checkerboard of 0 / 255):
	// the integer sums must not overflow
	cv::Mat board(64, 64, CV_8UC1);
	for (int v = 0; v < board.rows; v++)
		for (int u = 0; u < board.cols; u++)
			board.at<uint8_t>(v, u) = ((u / 2 + v / 2) % 2) ? 255 : 0;
	for (const int window : {9, 45})
		EXPECT_LT(maxRelTensorDiff(structureTensor(board, window),
		                           tensorReference(board, window)),
		          1e-6)
		    << window;
}

TEST(ObservedFlow, KeepsTheTensorAndFlowItReturned)
{
	// The pipeline keeps a frame's flow and tensor while the next frame's
	// flow is computed: the next compute() must not write into them.
	FlowParams p;
	p.visible_change_grey = 4;
	ObservedFlow of(p);
	const cv::Mat a = test::texture(160, 120, 1),
	              b = test::texture(160, 120, 2),
	              c = test::texture(160, 120, 3);
	const cv::Matx33d H = rotationHomography(test::vgaCamera(160, 120),
	                                         CPose3D(0, 0, 0, 0.01, 0.02, 0));
	cv::Mat flow1 = of.computeDerotated(a, b, H);
	cv::Mat tensor1 = of.tensor();
	const cv::Mat flow1Copy = flow1.clone(), tensor1Copy = tensor1.clone();
	for (int k = 0; k < 3; k++)
	{
		const cv::Mat& cur = k % 2 ? b : c;
		const cv::Mat flow2 = of.computeDerotated(b, cur, H);
		EXPECT_NE(flow2.data, flow1.data);
		EXPECT_NE(of.tensor().data, tensor1.data);
		EXPECT_EQ(cv::norm(flow1, flow1Copy, cv::NORM_INF), 0.0);
		EXPECT_EQ(cv::norm(tensor1, tensor1Copy, cv::NORM_INF), 0.0);
		// a reused buffer holds the right tensor
		EXPECT_EQ(cv::norm(of.tensor(), structureTensor(cur, 9), cv::NORM_INF),
		          0.0);
	}
	// once released, the tensor's memory may serve again; results unchanged
	tensor1.release();
	flow1.release();
	for (int k = 0; k < 3; k++)
	{
		const cv::Mat& cur = k % 2 ? a : c;
		of.compute(b, cur);
		EXPECT_EQ(cv::norm(of.tensor(), structureTensor(cur, 9), cv::NORM_INF),
		          0.0);
	}
	// without the gate (and refine_pose none) no tensor
	FlowParams off;
	off.visible_change_grey = 0;
	ObservedFlow plain(off);
	plain.compute(a, b);
	EXPECT_TRUE(plain.tensor().empty());
}

TEST(ExpectedFlow, ExactFlowEqualsTheDoubleFormula)
{
	// Motions between frames up to 15 cm and 8.6 deg per axis, depths from
	// 0.2 m: the previous camera's z stays >= ~0.1 m, where float rounds the
	// projection by < 1e-3 px (the error grows with (z + |t|) / Z).
	std::mt19937 rng(9);
	std::uniform_real_distribution<double> ang(-0.15, 0.15), tr(-0.15, 0.15);
	std::uniform_real_distribution<float> dz(0.2f, 12.0f);
	for (const cv::Size s : {cv::Size(640, 480), cv::Size(101, 37)})
		for (int k = 0; k < 8; k++)
		{
			const auto cam = test::vgaCamera(s.width, s.height);
			const CPose3D T(tr(rng), tr(rng), tr(rng), ang(rng), ang(rng),
			                ang(rng));
			cv::Mat z(s, CV_32FC1);
			for (int v = 0; v < s.height; v++)
				for (int u = 0; u < s.width; u++) z.at<float>(v, u) = dz(rng);
			// no reading, invalid readings
			const float bad[] = {0.0f, -1.0f, kNaN, kInf, -kInf};
			for (int i = 0; i < 5; i++) z.at<float>(i, 3 * i) = bad[i];
			const auto& R = T.getRotationMatrix();
			cv::Mat ref(s, CV_32FC2);
			for (int v = 0; v < s.height; v++)
				for (int u = 0; u < s.width; u++)
				{
					const double d = z.at<float>(v, u);
					const double x = (u - cam.cx()) / cam.fx() * d,
					             y = (v - cam.cy()) / cam.fy() * d;
					const double X = R(0, 0) * x + R(0, 1) * y + R(0, 2) * d +
					                 T.x(),
					             Y = R(1, 0) * x + R(1, 1) * y + R(1, 2) * d +
					                 T.y(),
					             Z = R(2, 0) * x + R(2, 1) * y + R(2, 2) * d +
					                 T.z();
					const bool valid = std::isfinite(d) && d > 0 && Z > 1e-6;
					ref.at<cv::Vec2f>(v, u) =
					    valid
					        ? cv::Vec2f(float(cam.fx() * X / Z + cam.cx() - u),
					                    float(cam.fy() * Y / Z + cam.cy() - v))
					        : cv::Vec2f(kNaN, kNaN);
				}
			int mismatch = 0;
			EXPECT_LT(maxFlowDiff(expectedFlowExact(z, cam, T), ref, &mismatch),
			          1e-3)
			    << k;
			EXPECT_EQ(mismatch, 0) << k;
		}
}

namespace
{
/** The labels by their definition (consistency.h), one pixel at a time. */
cv::Mat labelsReference(const cv::Mat& obs, const cv::Mat& exp,
                        const cv::Mat& depth, const FlowParams& p,
                        const cv::Mat* S, double thr, LabelStats* st)
{
	cv::Mat l(depth.size(), CV_8SC1);
	*st = {};
	const double W = depth.cols - 1, H = depth.rows - 1;
	for (int v = 0; v < depth.rows; v++)
		for (int u = 0; u < depth.cols; u++)
		{
			const double z = depth.at<float>(v, u);
			const auto o = obs.at<cv::Vec2f>(v, u), e = exp.at<cv::Vec2f>(v, u);
			const double eu = float(u + e[0]), ev = float(v + e[1]),
			             ou = float(u + o[0]), ov = float(v + o[1]);
			int8_t lab = kNoLabel;
			if (std::isfinite(z) && z > 0 && z <= p.max_depth_m &&
			    std::isfinite(eu) && std::isfinite(ev) && std::isfinite(ou) &&
			    std::isfinite(ov) && eu >= 0 && ev >= 0 && ou >= 0 && ov >= 0 &&
			    eu <= W && ev <= H && ou <= W && ov <= H)
			{
				const double du = o[0] - e[0], dv = o[1] - e[1];
				lab = du * du + dv * dv > thr * thr ? kDiff : kNotDiff;
				if (lab == kDiff && S)
				{
					const auto s = S->at<cv::Vec3f>(v, u);
					if (du * du * s[0] + 2 * du * dv * s[1] + dv * dv * s[2] <
					    p.visible_change_grey * p.visible_change_grey)
						lab = kNotDiff;
				}
			}
			l.at<int8_t>(v, u) = lab;
			(lab == kDiff      ? st->diff
			 : lab == kNotDiff ? st->notDiff
			                   : st->none)++;
		}
	return l;
}
}  // namespace

TEST(Consistency, LabelsEqualThePlainDefinition)
{
	std::mt19937 rng(3);
	std::uniform_real_distribution<float> dz(0.3f, 8.0f), uni(0.0f, 1.0f);
	std::uniform_real_distribution<double> phi(0, 2 * M_PI);
	for (const cv::Size s : {cv::Size(320, 240), cv::Size(67, 29)})
		for (const bool gate : {false, true})
		{
			const auto cam = test::vgaCamera(s.width, s.height);
			FlowParams p;
			p.diff_threshold_px = 1.3;
			p.max_depth_m = 5.3;  // not a float: the comparison's edge
			p.visible_change_grey = gate ? 4 : 0;
			cv::Mat z(s, CV_32FC1);
			for (int v = 0; v < s.height; v++)
				for (int u = 0; u < s.width; u++) z.at<float>(v, u) = dz(rng);
			z.at<float>(0, 0) = float(p.max_depth_m);  // rounds above it
			z.at<float>(0, 1) = std::nextafter(float(p.max_depth_m), 0.0f);
			const cv::Mat exp = randomFlow(s.width, s.height, 6, rng);
			cv::Mat obs = exp.clone();
			// differences of every kind: clearly under / over the threshold,
			// within float rounding of it, NaN, infinite, leaving the image
			for (int v = 0; v < s.height; v++)
				for (int u = 0; u < s.width; u++)
				{
					const double r = uni(rng);
					double mag = 3 * uni(rng);
					if (r < 0.3)
						mag =
						    p.diff_threshold_px * (1 + 1e-7 * (uni(rng) - 0.5));
					const double a = phi(rng);
					auto& o = obs.at<cv::Vec2f>(v, u);
					o[0] += float(mag * std::cos(a));
					o[1] += float(mag * std::sin(a));
					if (r > 0.97) o[0] = kNaN;
					if (r > 0.985) o[1] = kInf;
					if (r > 0.99) obs.at<cv::Vec2f>(v, u)[0] = -500;
				}
			const cv::Mat grey = test::texture(s.width, s.height, 8);
			const cv::Mat S = structureTensor(grey, 9);
			LabelStats st, stRef;
			const cv::Mat lab = labelConsistency(obs, exp, z, cam, CPose3D(), p,
			                                     &st, gate ? &S : nullptr);
			const cv::Mat ref =
			    labelsReference(obs, exp, z, p, gate ? &S : nullptr,
			                    p.diff_threshold_px, &stRef);
			EXPECT_EQ(cv::countNonZero(lab != ref), 0) << s << " gate " << gate;
			EXPECT_EQ(st.diff, stRef.diff);
			EXPECT_EQ(st.notDiff, stRef.notDiff);
			EXPECT_EQ(st.none, stRef.none);
			EXPECT_GT(stRef.diff, 0u);
			EXPECT_GT(stRef.notDiff, 0u);
		}
}
