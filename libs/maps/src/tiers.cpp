// Tier 1 (background subtraction) and tier 2 (flow consistency): the
// posterior computations (docs/model.md).
#include <bims/maps/CMotionGridBase.h>
#include <bims/maps/closed_form.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace bims::maps
{
CBackgroundSubtractionGrid::CBackgroundSubtractionGrid(const GridParams& p)
    : CMotionGridBase(p)
{
}

void CBackgroundSubtractionGrid::posterior(const GridParams& p,
                                           const FrameCloud& f,
                                           const std::vector<float>& priorO,
                                           std::vector<float>& post)
{
	if (priorO.size() != f.cells.size())
		throw std::invalid_argument(
		    "CBackgroundSubtractionGrid::posterior: one O- per cell expected");
	const double logLambda = std::log(p.reading_lambda);
	post.resize(f.cells.size());
	// The hit evidence depends on n only; cache the common small counts.
	double hitCache[64];
	for (uint32_t n = 0; n < 64; ++n)
		hitCache[n] = n ? hitLogOdds(p.p_miss, logLambda, n) : 0;
	// O- takes few distinct values (saturated cells): memoise its prior.
	float lastO = std::nanf("");
	double lastQ = 0;
	for (size_t i = 0; i < f.cells.size(); ++i)
	{
		const uint32_t n = f.hits[i];
		const double hit =
		    n < 64 ? hitCache[n] : hitLogOdds(p.p_miss, logLambda, n);
		if (!(priorO[i] == lastO))
		{
			lastO = priorO[i];
			lastQ = backgroundPriorLogOdds(lastO, p.bg_transition_eps);
		}
		post[i] = float(lastQ + hit);
	}
}

CFlowConsistencyGrid::CFlowConsistencyGrid(const GridParams& p)
    : CMotionGridBase(p)
{
}

void CFlowConsistencyGrid::setPendingLabels(PixelLabels labels)
{
	pending_ = std::move(labels);
}

void CFlowConsistencyGrid::countLabels(const FrameCloud& f,
                                       const PixelLabels& labels,
                                       std::vector<uint32_t>& k,
                                       std::vector<uint32_t>& l)
{
	k.assign(f.cells.size(), 0);
	l.assign(f.cells.size(), 0);
	if (labels.label.empty()) return;  // no labels: no flow evidence
	if (labels.width != f.K.width || labels.height != f.K.height ||
	    labels.label.size() != size_t(labels.width) * size_t(labels.height))
		throw std::invalid_argument(
		    "CFlowConsistencyGrid: labels are " + std::to_string(labels.width) +
		    "x" + std::to_string(labels.height) + " but the frame is " +
		    std::to_string(f.K.width) + "x" + std::to_string(f.K.height));
	for (size_t j = 0; j < f.pixel.size(); ++j)
	{
		const int8_t lab = labels.label[f.pixel[j]];
		if (lab == 1)
			k[f.cellOfPoint[j]]++;
		else if (lab == 0)
			l[f.cellOfPoint[j]]++;
	}
}

void CFlowConsistencyGrid::posterior(const FrameCloud& f,
                                     const PixelLabels& labels,
                                     const std::vector<float>& tier1,
                                     std::vector<float>& post) const
{
	if (tier1.size() != f.cells.size())
		throw std::invalid_argument(
		    "CFlowConsistencyGrid::posterior: one tier-1 value per cell "
		    "expected");
	const auto& p = params_;
	const double logLambda = std::log(p.flow_lambda);
	const bool veto = p.flow_evidence == FlowEvidence::Veto;
	// The update is additive in log-odds: flowPosterior(lI, k, l) - lI
	// depends on (k, l) only. Small counts are tabulated (once per
	// parameter set).
	constexpr uint32_t T = kTable;
	auto& tab = delta_;
	if (tab.d.empty() || tab.tau != p.flow_transition_tau ||
	    tab.pMiss != p.p_miss || tab.logLambda != logLambda || tab.veto != veto)
	{
		tab.tau = p.flow_transition_tau;
		tab.pMiss = p.p_miss;
		tab.logLambda = logLambda;
		tab.veto = veto;
		tab.d.resize(T * T);
		for (uint32_t a = 0; a < T; ++a)
			for (uint32_t b = 0; b < T; ++b)
				tab.d[a * T + b] = flowPosterior(
				    0, p.flow_transition_tau, p.p_miss, logLambda, a, b, veto);
	}
	// Diff (k) and notDiff (l) counts per cell, as countLabels(): packed
	// k | l << 16 in one word (half the memory of two counters) when no
	// cell has 2^16 readings, else interleaved.
	const size_t m = f.cells.size();
	const uint32_t* hits = f.hits.data();
	uint32_t maxHits = 0;
	for (size_t i = 0; i < m; ++i) maxHits = std::max(maxHits, hits[i]);
	const bool packed = maxHits < (uint32_t(1) << 16);
	counts_.assign(packed ? m : 2 * m, 0);
	if (!labels.label.empty())
	{
		if (labels.width != f.K.width || labels.height != f.K.height ||
		    labels.label.size() != size_t(labels.width) * size_t(labels.height))
			throw std::invalid_argument(
			    "CFlowConsistencyGrid: labels are " +
			    std::to_string(labels.width) + "x" +
			    std::to_string(labels.height) + " but the frame is " +
			    std::to_string(f.K.width) + "x" + std::to_string(f.K.height));
		// Without a branch on the label: an unlabelled reading (-1) adds 0.
		uint32_t* kl = counts_.data();
		const int8_t* lab = labels.label.data();
		const uint32_t* cop = f.cellOfPoint.data();
		const uint32_t* pix = f.pixel.data();
		const size_t n = f.pixel.size();
		if (packed)
			for (size_t j = 0; j < n; ++j)
			{
				const int8_t v = lab[pix[j]];
				kl[cop[j]] += uint32_t(v == 1) | (uint32_t(v == 0) << 16);
			}
		else
			for (size_t j = 0; j < n; ++j)
			{
				const int8_t v = lab[pix[j]];
				kl[2 * size_t(cop[j]) + (v == 0)] += uint32_t(v == 0 || v == 1);
			}
	}
	post.resize(m);
	const uint32_t* kl = counts_.data();
	for (size_t i = 0; i < m; ++i)
	{
		const uint32_t k = packed ? kl[i] & 0xffff : kl[2 * i],
		               l = packed ? kl[i] >> 16 : kl[2 * i + 1];
		const double d = (k < T && l < T)
		                     ? tab.d[k * T + l]
		                     : flowPosterior(0, p.flow_transition_tau, p.p_miss,
		                                     logLambda, k, l, veto);
		post[i] = float(tier1[i] + d);
	}
}

void CFlowConsistencyGrid::computePosterior(const FrameCloud& f,
                                            const std::vector<float>& priorO,
                                            std::vector<float>& post)
{
	CBackgroundSubtractionGrid::posterior(params_, f, priorO, t1scratch_);
	PixelLabels labels = std::move(pending_);
	pending_ = PixelLabels();
	posterior(f, labels, t1scratch_, post);
}

}  // namespace bims::maps
