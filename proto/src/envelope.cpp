#include "hfmpm/proto/envelope.hpp"

#include <google/protobuf/descriptor.h>
#include <google/protobuf/io/coded_stream.h>
#include <google/protobuf/io/zero_copy_stream_impl_lite.h>
#include <google/protobuf/unknown_field_set.h>

#include <cmath>
#include <cstdio>

#include <vector>

namespace hfmpm::proto {
namespace {

void collect_non_finite(const google::protobuf::Message& message, const std::string& prefix,
                        std::vector<NonFinite>& out) {
  namespace pb = google::protobuf;
  const auto* reflection = message.GetReflection();
  std::vector<const pb::FieldDescriptor*> fields;
  reflection->ListFields(message, &fields);  // proto3: NaN and inf are not 0, so they are listed
  for (const auto* field : fields) {
    const std::string key = prefix + field->name();
    const int count = field->is_repeated() ? reflection->FieldSize(message, field) : 1;
    for (int i = 0; i < count; ++i) {
      const std::string k = field->is_repeated() ? key + "[" + std::to_string(i) + "]" : key;
      switch (field->cpp_type()) {
        case pb::FieldDescriptor::CPPTYPE_DOUBLE: {
          const double v = field->is_repeated() ? reflection->GetRepeatedDouble(message, field, i)
                                                : reflection->GetDouble(message, field);
          if (!std::isfinite(v)) out.push_back({k, v});
          break;
        }
        case pb::FieldDescriptor::CPPTYPE_FLOAT: {
          const double v = field->is_repeated() ? reflection->GetRepeatedFloat(message, field, i)
                                                : reflection->GetFloat(message, field);
          if (!std::isfinite(v)) out.push_back({k, v});
          break;
        }
        case pb::FieldDescriptor::CPPTYPE_MESSAGE:
          collect_non_finite(field->is_repeated() ? reflection->GetRepeatedMessage(message, field, i)
                                                  : reflection->GetMessage(message, field),
                             k + ".", out);
          break;
        default:
          break;
      }
    }
  }
}

// True if `message` or any message set inside it carries unknown fields.
bool has_unknown_fields(const google::protobuf::Message& message) {
  const auto* reflection = message.GetReflection();
  if (!reflection->GetUnknownFields(message).empty()) return true;
  std::vector<const google::protobuf::FieldDescriptor*> fields;
  reflection->ListFields(message, &fields);
  for (const auto* field : fields) {
    if (field->cpp_type() != google::protobuf::FieldDescriptor::CPPTYPE_MESSAGE) continue;
    if (field->is_repeated()) {
      for (int i = 0; i < reflection->FieldSize(message, field); ++i) {
        if (has_unknown_fields(reflection->GetRepeatedMessage(message, field, i))) return true;
      }
    } else if (has_unknown_fields(reflection->GetMessage(message, field))) {
      return true;
    }
  }
  return false;
}

}  // namespace

std::string encode(const protocol::Envelope& envelope) {
  std::string bytes;
  if (!envelope.SerializeToString(&bytes)) throw ProtocolError("could not serialize an Envelope");
  return bytes;
}

protocol::Envelope decode(const void* data, std::size_t size, std::string_view from) {
  protocol::Envelope envelope;
  if (size > static_cast<std::size_t>(INT32_MAX) || !envelope.ParseFromArray(data, static_cast<int>(size))) {
    throw ProtocolError("malformed message from " + std::string(from) + ": " + std::to_string(size) +
                        " bytes that do not parse as an hfmpm Envelope");
  }
  if (has_unknown_fields(envelope)) {
    throw ProtocolError("malformed message from " + std::string(from) + ": it carries fields that protocol version " +
                        std::to_string(kProtocolVersion) + " does not define (a different protocol, or garbage bytes)");
  }
  if (envelope.body_case() == protocol::Envelope::BODY_NOT_SET) {
    throw ProtocolError("malformed message from " + std::string(from) + ": an Envelope with no body (" +
                        std::to_string(size) + " bytes)");
  }
  return envelope;
}

std::vector<NonFinite> non_finite_numbers(const google::protobuf::Message& message) {
  std::vector<NonFinite> out;
  collect_non_finite(message, "", out);
  return out;
}

std::string_view body_name(const protocol::Envelope& envelope) {
  const auto* field = envelope.GetDescriptor()->FindFieldByNumber(static_cast<int>(envelope.body_case()));
  return field ? std::string_view(field->name()) : std::string_view("empty");
}

std::string_view role_name(protocol::Role role) {
  switch (role) {
    case protocol::SOLID:
      return "solid";
    case protocol::FLUID:
      return "fluid";
    case protocol::COUPLER:
      return "coupler";
    default:
      return "unspecified";
  }
}

std::string scene_hash(const scene::Scene& scene) {
  std::string bytes;
  {
    google::protobuf::io::StringOutputStream stream(&bytes);
    google::protobuf::io::CodedOutputStream coded(&stream);
    coded.SetSerializationDeterministic(true);
    if (!scene.SerializeToCodedStream(&coded)) throw std::runtime_error("cannot serialize the scene to hash it");
  }
  std::uint64_t hash = 14695981039346656037ull;
  for (unsigned char c : bytes) {
    hash ^= c;
    hash *= 1099511628211ull;
  }
  char text[17] = {};
  std::snprintf(text, sizeof(text), "%016llx", static_cast<unsigned long long>(hash));
  return text;
}

}  // namespace hfmpm::proto
