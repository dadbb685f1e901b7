#include <bims/common/config.h>
#include <bims/common/frames.h>
#include <bims/io/output_paths.h>
#include <bims/sim/imu.h>
#include <bims/sim/rng.h>
#include <mrpt/system/datetime.h>

#include <Eigen/SVD>
#include "ini_vector.h"

#include <cmath>
#include <cstdio>
#include <stdexcept>

namespace bims::sim
{
using detail::kDeg;
using detail::stdv;
using detail::vec3;
namespace
{
Eigen::Vector3d gaussVec(Rng& r)
{
	return {r.gauss(), r.gauss(), r.gauss()};
}
}  // namespace

ImuParams::ImuParams()
{
	setR_IC_ypr(-90, 0, -90);
}

void ImuParams::setR_IC_ypr(double y, double p, double r)
{
	R_IC = Eigen::AngleAxisd(y * kDeg, Eigen::Vector3d::UnitZ())
	           .toRotationMatrix() *
	       Eigen::AngleAxisd(p * kDeg, Eigen::Vector3d::UnitY())
	           .toRotationMatrix() *
	       Eigen::AngleAxisd(r * kDeg, Eigen::Vector3d::UnitX())
	           .toRotationMatrix();
}

Eigen::Vector3d ImuParams::earthField_W() const
{
	const double dip = magDipDeg * kDeg, dec = magDeclinationDeg * kDeg;
	return magField * Eigen::Vector3d(std::cos(dip) * std::cos(dec),
	                                  -std::cos(dip) * std::sin(dec),
	                                  -std::sin(dip));
}

Eigen::Vector3d ImuParams::field_W(const Eigen::Vector3d& p_W) const
{
	Eigen::Vector3d m = earthField_W();
	if (disturbance)
	{
		const double r = (p_W - disturbanceCenter).norm() / disturbanceRadius;
		if (r < 1) m += disturbanceField * (1 - r * r) * (1 - r * r);
	}
	return m;
}

void ImuParams::makeNoiseless()
{
	gyroNoiseDensity = gyroBiasRw = gyroBiasInit = 0;
	accNoiseDensity = accBiasRw = accBiasInit = 0;
	magNoiseDensity = magBiasRw = magBiasInit = orientationNoiseDeg = 0;
}

void ImuParams::loadFromConfigFile(const mrpt::config::CConfigFileBase& cfg,
                                   const std::string& imuSection,
                                   const std::string& calibSection)
{
	{
		ConfigSection s(cfg, imuSection);
		rateHz = s.getDouble("rate_hz", rateHz, 1, 10000);
		label = s.getString("label", label);
		if (label.empty() || label.find_first_of(" \t") != std::string::npos)
			s.fail("label", "must be a non-empty word");
		gyroNoiseDensity =
		    s.getDouble("gyro_noise_density", gyroNoiseDensity, 0, 1);
		gyroBiasRw = s.getDouble("gyro_bias_rw", gyroBiasRw, 0, 1);
		gyroBiasInit = s.getDouble("gyro_bias_init", gyroBiasInit, 0, 1);
		accNoiseDensity =
		    s.getDouble("acc_noise_density", accNoiseDensity, 0, 10);
		accBiasRw = s.getDouble("acc_bias_rw", accBiasRw, 0, 10);
		accBiasInit = s.getDouble("acc_bias_init", accBiasInit, 0, 10);
		magNoiseDensity =
		    s.getDouble("mag_noise_density", magNoiseDensity, 0, 1);
		magBiasRw = s.getDouble("mag_bias_rw", magBiasRw, 0, 1);
		magBiasInit = s.getDouble("mag_bias_init", magBiasInit, 0, 1);
		magField = s.getDouble("mag_field_gauss", magField, 0, 10);
		magDipDeg = s.getDouble("mag_dip_deg", magDipDeg, -90, 90);
		magDeclinationDeg =
		    s.getDouble("mag_declination_deg", magDeclinationDeg, -180, 180);
		disturbance = s.getBool("disturbance", disturbance);
		disturbanceCenter = vec3(s.getDoubles(
		    "disturbance_center", stdv(disturbanceCenter), 3, -1000, 1000));
		disturbanceRadius =
		    s.getDouble("disturbance_radius", disturbanceRadius, 0.01, 1000);
		disturbanceField = vec3(s.getDoubles(
		    "disturbance_field_gauss", stdv(disturbanceField), 3, -100, 100));
		orientation = s.getBool("orientation", orientation);
		orientationNoiseDeg =
		    s.getDouble("orientation_noise_deg", orientationNoiseDeg, 0, 90);
		if (s.getBool("noiseless", false)) makeNoiseless();
		s.finish();
	}
	{
		ConfigSection s(cfg, calibSection);
		const auto ypr =
		    s.getDoubles("R_IC_ypr_deg", {-90, 0, -90}, 3, -360, 360);
		setR_IC_ypr(ypr[0], ypr[1], ypr[2]);
		timeOffsetS = s.getDouble("time_offset_s", timeOffsetS, -1, 1);
		s.finish();
	}
}

ImuSimulator::ImuSimulator(const ImuParams& p, uint64_t seed)
    : p_(p), seed_(seed)
{
	Rng r(seed, 0x1B1A5);
	bg_ = p_.gyroBiasInit * gaussVec(r);
	ba_ = p_.accBiasInit * gaussVec(r);
	// Own streams for the magnetometer bias: the other channels do not change.
	Rng rm(seed, 0x3A6B1A5);
	bm_ = p_.magBiasInit * gaussVec(rm);
}

mrpt::obs::CObservationIMU::Ptr ImuSimulator::sample(const MotionModel& motion,
                                                     double tStamp,
                                                     double modelT0,
                                                     ImuTruth* truth)
{
	using namespace mrpt::obs;
	Rng r(seed_,
	      0x100000000ULL + n_);  // one stream per sample: order-independent
	if (n_ > 0)
	{
		const double dt = std::max(0.0, tStamp - lastT_);
		bg_ += p_.gyroBiasRw * std::sqrt(dt) * gaussVec(r);
		ba_ += p_.accBiasRw * std::sqrt(dt) * gaussVec(r);
	}
	if (n_ > 0)
	{
		Rng rw(seed_, 0x3A6B00000000ULL + n_);
		bm_ += p_.magBiasRw * std::sqrt(std::max(0.0, tStamp - lastT_)) *
		       gaussVec(rw);
	}
	lastT_ = tStamp;
	n_++;

	const double tTrue = tStamp - p_.timeOffsetS;
	const Kinematics k = motion.at(tTrue - modelT0);
	const Eigen::Matrix3d R_WI = k.R_WC * p_.R_IC.transpose();
	const Eigen::Vector3d g_W(0, 0, -kGravity);
	const Eigen::Vector3d w_I = p_.R_IC * k.omega_C;
	const Eigen::Vector3d f_I = R_WI.transpose() * (k.a_W - g_W);
	const Eigen::Vector3d m_I = R_WI.transpose() * p_.field_W(k.p_WC);

	const double sq = std::sqrt(p_.rateHz);
	const Eigen::Vector3d w =
	    w_I + bg_ + p_.gyroNoiseDensity * sq * gaussVec(r);
	const Eigen::Vector3d f = f_I + ba_ + p_.accNoiseDensity * sq * gaussVec(r);
	const Eigen::Vector3d m = m_I + bm_ + p_.magNoiseDensity * sq * gaussVec(r);

	auto o = CObservationIMU::Create();
	o->sensorLabel = p_.label;
	o->timestamp = mrpt::Clock::fromDouble(tStamp);
	o->set(IMU_X_ACC, f.x());
	o->set(IMU_Y_ACC, f.y());
	o->set(IMU_Z_ACC, f.z());
	o->set(IMU_WX, w.x());
	o->set(IMU_WY, w.y());
	o->set(IMU_WZ, w.z());
	o->set(IMU_MAG_X, m.x());
	o->set(IMU_MAG_Y, m.y());
	o->set(IMU_MAG_Z, m.z());
	const Eigen::Quaterniond q_WI(R_WI);
	if (p_.orientation)
	{
		const Eigen::Vector3d e = p_.orientationNoiseDeg * kDeg * gaussVec(r);
		Eigen::Quaterniond qn = q_WI;
		if (e.norm() > 0)
			qn = q_WI * Eigen::Quaterniond(
			                Eigen::AngleAxisd(e.norm(), e.normalized()));
		qn.normalize();
		o->set(IMU_ORI_QUAT_X, qn.x());
		o->set(IMU_ORI_QUAT_Y, qn.y());
		o->set(IMU_ORI_QUAT_Z, qn.z());
		o->set(IMU_ORI_QUAT_W, qn.w());
	}
	if (truth)
	{
		truth->tStamp = tStamp;
		truth->tTrue = tTrue;
		truth->omega_I = w_I;
		truth->f_I = f_I;
		truth->m_I = m_I;
		truth->gyroBias = bg_;
		truth->accBias = ba_;
		truth->magBias = bm_;
		truth->q_WI = q_WI;
	}
	return o;
}

std::vector<mrpt::obs::CObservationIMU::Ptr> synthesizeImu(
    const Trajectory& trajectory, const ImuParams& params, uint64_t seed,
    std::vector<ImuTruth>* truth)
{
	const SplineMotion motion(trajectory);
	ImuParams p = params;
	if (p.label.find("SYNTH") == std::string::npos) p.label += "_SYNTH";
	ImuSimulator sim(p, seed);
	std::vector<mrpt::obs::CObservationIMU::Ptr> out;
	if (truth) truth->clear();
	const double t0 = motion.tBegin(), t1 = motion.tEnd();
	const size_t n = size_t(std::floor((t1 - t0) * p.rateHz + 1e-9)) + 1;
	for (size_t i = 0; i < n; i++)
	{
		const double tTrue = t0 + double(i) / p.rateHz;
		ImuTruth tr;
		// Model time = absolute time (modelT0 = 0); the stamp carries the
		// offset.
		out.push_back(sim.sample(motion, tTrue + p.timeOffsetS, 0.0,
		                         truth ? &tr : nullptr));
		if (truth) truth->push_back(tr);
	}
	return out;
}

std::string imuTruthHeader()
{
	return "# bims-sim IMU ground truth, one line per IMU observation in the "
	       "rawlog.\n"
	       "# t_stamp[s] t_true[s] wx wy wz[rad/s, true angular rate in {I}] "
	       "fx fy fz[m/s^2, true specific force in {I}] mx my mz[gauss, true "
	       "field in {I}] "
	       "bgx bgy bgz[rad/s gyro bias] bax bay baz[m/s^2 accel bias] "
	       "qx qy qz qw[true R_WI] bmx bmy bmz[gauss magnetometer bias]\n";
}

std::string imuTruthLine(const ImuTruth& t)
{
	char buf[640];
	std::snprintf(buf, sizeof(buf),
	              "%.6f %.6f %.9f %.9f %.9f %.9f %.9f %.9f %.9f %.9f %.9f "
	              "%.9e %.9e %.9e %.9e %.9e %.9e "
	              "%.9f %.9f %.9f %.9f %.9e %.9e %.9e\n",
	              t.tStamp, t.tTrue, t.omega_I.x(), t.omega_I.y(),
	              t.omega_I.z(), t.f_I.x(), t.f_I.y(), t.f_I.z(), t.m_I.x(),
	              t.m_I.y(), t.m_I.z(), t.gyroBias.x(), t.gyroBias.y(),
	              t.gyroBias.z(), t.accBias.x(), t.accBias.y(), t.accBias.z(),
	              t.q_WI.x(), t.q_WI.y(), t.q_WI.z(), t.q_WI.w(), t.magBias.x(),
	              t.magBias.y(), t.magBias.z());
	return buf;
}

void loadSynthCalibration(const mrpt::config::CConfigFileBase& cfg,
                          ImuParams& imu)
{
	if (!cfg.sectionExists("calibration")) return;
	ConfigSection s(cfg, "calibration");
	if (s.has("R_IC"))
	{
		const auto v = s.getDoubles("R_IC", {}, 9, -1.0001, 1.0001);
		Eigen::Matrix3d M;
		M << v[0], v[1], v[2], v[3], v[4], v[5], v[6], v[7], v[8];
		Eigen::JacobiSVD<Eigen::Matrix3d> svd(
		    M, Eigen::ComputeFullU | Eigen::ComputeFullV);
		const Eigen::Matrix3d R = svd.matrixU() * svd.matrixV().transpose();
		if ((R - M).norm() > 1e-3 || R.determinant() < 0)
			s.fail("R_IC", "not a rotation matrix");
		imu.R_IC = R;
	}
	else if (s.has("R_IC_ypr_deg"))
	{
		const auto y = s.getDoubles("R_IC_ypr_deg", {}, 3, -360, 360);
		imu.setR_IC_ypr(y[0], y[1], y[2]);
	}
	imu.timeOffsetS = s.getDouble("time_offset_s", 0.0, -10.0, 10.0);
}

std::vector<mrpt::obs::CObservation::Ptr> synthesizeImportImu(
    const Trajectory& gt, const std::string& label,
    const mrpt::config::CConfigFileBase* calibration, uint64_t seed)
{
	ImuParams imu;
	imu.label = label;
	if (calibration) loadSynthCalibration(*calibration, imu);
	std::vector<mrpt::obs::CObservation::Ptr> obs;
	for (auto& o : synthesizeImu(gt, imu, seed)) obs.push_back(o);
	return obs;
}

void saveImuTruth(const std::string& path, const std::vector<ImuTruth>& truth)
{
	std::string text = imuTruthHeader();
	for (const auto& t : truth) text += imuTruthLine(t);
	writeFileAtomically(path, text);
}

}  // namespace bims::sim
