#include <bims/ros2/dds.h>
#include <dds/ddsi/ddsi_serdata.h>

#include <stdexcept>

namespace bims::ros2
{
std::string ddsTopicName(const std::string& topic)
{
	return "rt" + topic;
}

DdsEntity& DdsEntity::operator=(DdsEntity&& o) noexcept
{
	if (this != &o)
	{
		if (e_ > 0) dds_delete(e_);
		e_ = o.e_;
		o.e_ = 0;
	}
	return *this;
}

DdsEntity::~DdsEntity()
{
	if (e_ > 0) dds_delete(e_);
}

dds_entity_t ddsCheck(dds_entity_t rc, const std::string& what)
{
	if (rc < 0) throw std::runtime_error(what + ": " + dds_strretcode(rc));
	return rc;
}

dds_qos_t* sensorQos(int depth)
{
	dds_qos_t* q = dds_create_qos();
	dds_qset_reliability(q, DDS_RELIABILITY_BEST_EFFORT, 0);
	dds_qset_durability(q, DDS_DURABILITY_VOLATILE);
	dds_qset_history(q, DDS_HISTORY_KEEP_LAST, depth);
	return q;
}

dds_qos_t* outputQos(int depth)
{
	dds_qos_t* q = dds_create_qos();
	dds_qset_reliability(q, DDS_RELIABILITY_RELIABLE, DDS_MSECS(10));
	dds_qset_durability(q, DDS_DURABILITY_TRANSIENT_LOCAL);
	dds_qset_history(q, DDS_HISTORY_KEEP_LAST, depth);
	return q;
}

namespace
{
dds_entity_t topicOf(dds_entity_t participant, const std::string& topic,
                     const dds_topic_descriptor_t& desc)
{
	return ddsCheck(
	    dds_create_topic(participant, &desc, ddsTopicName(topic).c_str(),
	                     nullptr, nullptr),
	    "topic " + topic + " (" + desc.m_typename + ")");
}
}  // namespace

dds_entity_t createReader(dds_entity_t participant, const std::string& topic,
                          const dds_topic_descriptor_t& desc, int depth)
{
	const dds_entity_t t = topicOf(participant, topic, desc);
	dds_qos_t* q = sensorQos(depth);
	const dds_entity_t r = dds_create_reader(participant, t, q, nullptr);
	dds_delete_qos(q);
	return ddsCheck(r, "reader of " + topic);
}

dds_entity_t createWriter(dds_entity_t participant, const std::string& topic,
                          const dds_topic_descriptor_t& desc, int depth,
                          bool sensor)
{
	const dds_entity_t t = topicOf(participant, topic, desc);
	dds_qos_t* q = sensor ? sensorQos(depth) : outputQos(depth);
	const dds_entity_t w = dds_create_writer(participant, t, q, nullptr);
	dds_delete_qos(q);
	return ddsCheck(w, "writer of " + topic);
}

std::vector<CdrSample> takeCdr(dds_entity_t reader, size_t max)
{
	std::vector<CdrSample> out;
	while (out.size() < max)
	{
		ddsi_serdata* sd = nullptr;
		dds_sample_info_t info;
		const dds_return_t n =
		    dds_takecdr(reader, &sd, 1, &info, DDS_ANY_STATE);
		if (n <= 0) break;
		CdrSample s;
		s.valid = info.valid_data;
		if (s.valid)
		{
			const uint32_t size = ddsi_serdata_size(sd);
			s.bytes.resize(size);
			ddsi_serdata_to_ser(sd, 0, size, s.bytes.data());
		}
		ddsi_serdata_unref(sd);
		out.push_back(std::move(s));
	}
	return out;
}

}  // namespace bims::ros2
