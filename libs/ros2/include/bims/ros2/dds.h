// Cyclone DDS (its C API, Debian's 0.10.2) as a ROS 2 middleware does it
// (rmw_cyclonedds): topic "/a/b" is DDS topic "rt/a/b", type
// <pkg>/msg/<Type> is "<pkg>::msg::dds_::<Type>_" (the C types idlc makes
// of idl/ros2_types.idl). Received samples are taken as their CDR bytes
// and read by bims's own guarded decoder (bims/bag/cdr.h); published ones
// are written from the C types by Cyclone. docs/ros2.md.
#pragma once

#include <dds/dds.h>

#include <cstdint>
#include <string>
#include <vector>

namespace bims::ros2
{
/** "rt" + \a topic (a ROS 2 topic starting with '/'). */
std::string ddsTopicName(const std::string& topic);

/** An entity deleted (with its children) when this goes. */
class DdsEntity
{
 public:
	DdsEntity() = default;
	explicit DdsEntity(dds_entity_t e) : e_(e) {}
	DdsEntity(DdsEntity&& o) noexcept : e_(o.e_) { o.e_ = 0; }
	DdsEntity& operator=(DdsEntity&& o) noexcept;
	DdsEntity(const DdsEntity&) = delete;
	DdsEntity& operator=(const DdsEntity&) = delete;
	~DdsEntity();
	dds_entity_t get() const { return e_; }

 private:
	dds_entity_t e_ = 0;
};

/** Throws std::runtime_error "WHAT: <dds's error text>" when \a rc < 0;
 * returns it otherwise. */
dds_entity_t ddsCheck(dds_entity_t rc, const std::string& what);

/** The QoS of sensor drivers (and rclcpp's SensorDataQoS): best effort,
 * volatile, keep last \a depth. */
dds_qos_t* sensorQos(int depth);

/** The QoS of bims's own topics: reliable, transient local, keep last
 * \a depth: what best-effort and reliable, volatile and transient-local
 * subscribers all match (e.g. Foxglove's, which asks for reliable and
 * transient local); a write waits at most 10 ms for a slow reader. */
dds_qos_t* outputQos(int depth);

/** A reader of ROS 2 topic \a topic with type \a desc in \a participant. */
dds_entity_t createReader(dds_entity_t participant, const std::string& topic,
                          const dds_topic_descriptor_t& desc, int depth);
/** A writer, the same way: outputQos, or sensorQos when \a sensor. */
dds_entity_t createWriter(dds_entity_t participant, const std::string& topic,
                          const dds_topic_descriptor_t& desc, int depth,
                          bool sensor = false);

/** One sample taken from a reader as its serialized bytes (the CDR
 * encapsulation header first). */
struct CdrSample
{
	std::vector<uint8_t> bytes;
	bool valid = false;  ///< false: a state change without data
};
/** Takes the samples waiting at \a reader (at most \a max). */
std::vector<CdrSample> takeCdr(dds_entity_t reader, size_t max = 64);

}  // namespace bims::ros2
