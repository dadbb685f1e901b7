#include <bims/common/config.h>
#include <bims/common/share.h>
#include <bims/sim/simulator.h>
#include <mrpt/config/CConfigFile.h>

#include <algorithm>
#include <fstream>
#include <stdexcept>

namespace bims::sim
{
namespace
{
bool startsWith(const std::string& s, const std::string& p)
{
	return s.size() >= p.size() && s.compare(0, p.size(), p) == 0;
}
}  // namespace

SimConfig SimConfig::load(const std::string& given)
{
	// "sim/crowded.ini": the preset of share/bims
	const std::string path = bims::resolvePreset(given);
	{
		std::ifstream f(path);
		if (!f)
			throw std::runtime_error(path + ": cannot open scene file" +
			                         bims::presetHint(path));
	}
	const auto file = bims::openIniFile(path);
	const mrpt::config::CConfigFile& ini = *file;
	SimConfig c;
	c.file = path;
	checkSections(ini,
	              {"sim", "camera", "depth", "rgb", "imu", "calibration",
	               "motion", "room"},
	              {"pendulum", "box", "walker"});
	{
		ConfigSection s(ini, "sim", true);
		c.seq.frames = int(s.getInt("frames", c.seq.frames, 1, 1000000));
		c.seq.fps = s.getDouble("fps", c.seq.fps, 1, 1000);
		c.seq.rgbdLabel = s.getString("rgbd_label", c.seq.rgbdLabel);
		if (c.seq.rgbdLabel.empty() ||
		    c.seq.rgbdLabel.find_first_of(" \t") != std::string::npos)
			s.fail("rgbd_label", "must be a non-empty word");
		c.seq.startTime = s.getDouble("start_time", c.seq.startTime, 0, 4e9);
		c.seq.gzLevel = int(s.getInt("gz_level", c.seq.gzLevel, 0, 9));
		c.seq.pixelLabels = s.getBool("pixel_labels", c.seq.pixelLabels);
		s.finish();
	}
	c.camera.loadFromConfigFile(ini, "camera");
	c.depth.loadFromConfigFile(ini, "depth");
	c.rgb.loadFromConfigFile(ini, "rgb");
	c.imu.loadFromConfigFile(ini, "imu", "calibration");
	if (c.imu.label == c.seq.rgbdLabel)
		ConfigSection(ini, "imu")
		    .fail("label", "must differ from [sim] rgbd_label");
	c.motion.loadFromConfigFile(ini, "motion");
	c.room.loadFromConfigFile(ini, "room");

	std::vector<std::string> sections;
	ini.getAllSections(sections);
	std::sort(sections.begin(), sections.end());
	for (const auto& s : sections)
	{
		if (startsWith(s, "pendulum"))
		{
			PendulumParams p;
			p.loadFromConfigFile(ini, s);
			c.pendulums.emplace_back(s, p);
		}
		else if (startsWith(s, "box"))
		{
			SlidingBoxParams p;
			p.loadFromConfigFile(ini, s);
			c.boxes.emplace_back(s, p);
		}
		else if (startsWith(s, "walker"))
		{
			WalkerParams p;
			p.loadFromConfigFile(ini, s);
			c.walkers.emplace_back(s, p);
		}
	}
	if (c.pendulums.size() + c.boxes.size() + c.walkers.size() > 250)
		throw ConfigError(path + ": at most 250 moving objects");
	return c;
}

Scene SimConfig::buildScene() const
{
	Scene scene;
	buildRoom(room, scene);
	for (const auto& [n, p] : pendulums)
		scene.objects.push_back(makePendulum(n, p));
	for (const auto& [n, p] : boxes)
		scene.objects.push_back(makeSlidingBox(n, p));
	for (const auto& [n, p] : walkers)
		scene.objects.push_back(makeWalker(n, p));
	return scene;
}

}  // namespace bims::sim
