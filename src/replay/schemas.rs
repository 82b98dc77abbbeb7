//! Schemas embedded in the output (and used to write test bags): ROS 2
//! message definitions (`ros2msg`: the type's definition, then each
//! dependency after a line of 80 `=` and `MSG: pkg/Type`, as rosbag2 writes
//! them), and JSON schemas (`jsonschema`) for the profile and the picture.

/// `ros2msg` schema encoding.
pub const ROS2MSG: &str = "ros2msg";
/// `cdr` message encoding.
pub const CDR: &str = "cdr";
/// `jsonschema` schema encoding.
pub const JSONSCHEMA: &str = "jsonschema";
/// `json` message encoding.
pub const JSON: &str = "json";

const SEP: &str =
    "================================================================================\n";

const HEADER: &str = "builtin_interfaces/Time stamp\nstring frame_id\n";
const TIME: &str = "int32 sec\nuint32 nanosec\n";

fn with_deps(main: &str, deps: &[(&str, &str)]) -> String {
    let mut s = main.to_owned();
    for (name, def) in deps {
        s.push_str(SEP);
        s.push_str("MSG: ");
        s.push_str(name);
        s.push('\n');
        s.push_str(def);
    }
    s
}

/// `geometry_msgs/msg/Vector3Stamped`.
pub const VECTOR3_STAMPED: &str = "geometry_msgs/msg/Vector3Stamped";
/// `std_msgs/msg/Float64`.
pub const FLOAT64: &str = "std_msgs/msg/Float64";
/// `sensor_msgs/msg/PointCloud2`.
pub const POINT_CLOUD2: &str = "sensor_msgs/msg/PointCloud2";
/// `tf2_msgs/msg/TFMessage` (`/tf_static`: the sensor's mounting).
pub const TF_MESSAGE: &str = "tf2_msgs/msg/TFMessage";
/// `std_msgs/msg/String` (tests: an unrelated topic).
pub const STRING: &str = "std_msgs/msg/String";
/// The profile channel's schema name.
pub const PROFILE: &str = "gaze_lidar.Profile";
/// Foxglove's 3D scene message.
pub const SCENE_UPDATE: &str = "foxglove.SceneUpdate";

/// The `ros2msg` definition of one of the ROS types above.
#[must_use]
pub fn ros2msg(name: &str) -> Option<String> {
    let std_header = ("std_msgs/Header", HEADER);
    let time = ("builtin_interfaces/Time", TIME);
    Some(match name {
        VECTOR3_STAMPED => with_deps(
            "std_msgs/Header header\nVector3 vector\n",
            &[
                std_header,
                time,
                ("geometry_msgs/Vector3", "float64 x\nfloat64 y\nfloat64 z\n"),
            ],
        ),
        FLOAT64 => "float64 data\n".to_owned(),
        TF_MESSAGE => with_deps(
            "geometry_msgs/TransformStamped[] transforms\n",
            &[
                (
                    "geometry_msgs/TransformStamped",
                    "std_msgs/Header header\nstring child_frame_id\nTransform transform\n",
                ),
                std_header,
                time,
                (
                    "geometry_msgs/Transform",
                    "Vector3 translation\nQuaternion rotation\n",
                ),
                ("geometry_msgs/Vector3", "float64 x\nfloat64 y\nfloat64 z\n"),
                (
                    "geometry_msgs/Quaternion",
                    "float64 x 0\nfloat64 y 0\nfloat64 z 0\nfloat64 w 1\n",
                ),
            ],
        ),
        STRING => "string data\n".to_owned(),
        POINT_CLOUD2 => with_deps(
            "std_msgs/Header header\nuint32 height\nuint32 width\nPointField[] fields\nbool is_bigendian\nuint32 point_step\nuint32 row_step\nuint8[] data\nbool is_dense\n",
            &[
                std_header,
                time,
                (
                    "sensor_msgs/PointField",
                    "uint8 INT8=1\nuint8 UINT8=2\nuint8 INT16=3\nuint8 UINT16=4\nuint8 INT32=5\nuint8 UINT32=6\nuint8 FLOAT32=7\nuint8 FLOAT64=8\nstring name\nuint32 offset\nuint8 datatype\nuint32 count\n",
                ),
            ],
        ),
        _ => return None,
    })
}

/// JSON schema of the profile channel: a `gaze-lidar/profile@1` document
/// (DESIGN §3) as `gaze-lidar check` reads it.
pub const PROFILE_JSONSCHEMA: &str = r#"{
  "$schema": "https://json-schema.org/draft/2020-12/schema",
  "title": "gaze-lidar/profile@1",
  "type": "object",
  "required": ["format", "frame_rate_hz", "pulse_rate_hz", "average_power_w", "power_accounting", "gaze_deg", "limits", "bins"],
  "properties": {
    "format": {"const": "gaze-lidar/profile@1"},
    "frame_rate_hz": {"type": "number"},
    "pulse_rate_hz": {"type": "number"},
    "average_power_w": {"type": "number"},
    "power_accounting": {"enum": ["time", "angle"]},
    "gaze_deg": {"type": ["number", "null"]},
    "limits": {"type": "object"},
    "bins": {
      "type": "array",
      "items": {
        "type": "object",
        "required": ["start_deg", "width_deg", "power_w", "spin_start_rad_s", "spin_end_rad_s"],
        "properties": {
          "start_deg": {"type": "number"},
          "width_deg": {"type": "number"},
          "power_w": {"type": "number"},
          "spin_start_rad_s": {"type": "number"},
          "spin_end_rad_s": {"type": "number"}
        }
      }
    }
  }
}"#;

/// JSON schema of the subset of `foxglove.SceneUpdate` the picture uses
/// (Foxglove picks its 3D panel by the schema name; the field names are
/// Foxglove's schema's).
pub const SCENE_UPDATE_JSONSCHEMA: &str = r##"{
  "$schema": "https://json-schema.org/draft/2020-12/schema",
  "title": "foxglove.SceneUpdate",
  "type": "object",
  "properties": {
    "deletions": {"type": "array", "items": {"type": "object"}},
    "entities": {
      "type": "array",
      "items": {
        "type": "object",
        "properties": {
          "timestamp": {"$ref": "#/$defs/time"},
          "frame_id": {"type": "string"},
          "id": {"type": "string"},
          "lifetime": {"$ref": "#/$defs/time"},
          "frame_locked": {"type": "boolean"},
          "metadata": {"type": "array", "items": {"type": "object", "properties": {"key": {"type": "string"}, "value": {"type": "string"}}}},
          "triangles": {
            "type": "array",
            "items": {
              "type": "object",
              "properties": {
                "pose": {"$ref": "#/$defs/pose"},
                "points": {"type": "array", "items": {"$ref": "#/$defs/point"}},
                "color": {"$ref": "#/$defs/color"},
                "colors": {"type": "array", "items": {"$ref": "#/$defs/color"}},
                "indices": {"type": "array", "items": {"type": "integer"}}
              }
            }
          },
          "texts": {
            "type": "array",
            "items": {
              "type": "object",
              "properties": {
                "pose": {"$ref": "#/$defs/pose"},
                "billboard": {"type": "boolean"},
                "font_size": {"type": "number"},
                "scale_invariant": {"type": "boolean"},
                "color": {"$ref": "#/$defs/color"},
                "text": {"type": "string"}
              }
            }
          }
        }
      }
    }
  },
  "$defs": {
    "time": {"type": "object", "properties": {"sec": {"type": "integer"}, "nsec": {"type": "integer"}}},
    "point": {"type": "object", "properties": {"x": {"type": "number"}, "y": {"type": "number"}, "z": {"type": "number"}}},
    "pose": {"type": "object", "properties": {"position": {"$ref": "#/$defs/point"}, "orientation": {"type": "object", "properties": {"x": {"type": "number"}, "y": {"type": "number"}, "z": {"type": "number"}, "w": {"type": "number"}}}}},
    "color": {"type": "object", "properties": {"r": {"type": "number"}, "g": {"type": "number"}, "b": {"type": "number"}, "a": {"type": "number"}}}
  }
}"##;
