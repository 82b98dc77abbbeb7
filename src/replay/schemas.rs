//! Schemas embedded in the output (and used to write test bags): ROS 2
//! message definitions (`ros2msg`: the type's definition, then each
//! dependency after a line of 80 `=` and `MSG: pkg/Type`, as rosbag2 writes
//! them). Every output channel is `ros2msg` + CDR, so ROS tools (rosbags,
//! `mcap-ros2-support`, Foxglove, `ros2 bag play`) read all of it.

/// `ros2msg` schema encoding.
pub const ROS2MSG: &str = "ros2msg";
/// `cdr` message encoding.
pub const CDR: &str = "cdr";

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
/// `std_msgs/msg/String`: the profile channel (one profile@1 JSON
/// document a message).
pub const STRING: &str = "std_msgs/msg/String";
/// `visualization_msgs/msg/MarkerArray`: the picture of the profile.
pub const MARKER_ARRAY: &str = "visualization_msgs/msg/MarkerArray";

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
        // As ROS 2 Humble defines it (the texture and mesh-file fields of
        // later distributions absent: readers decode by this schema).
        MARKER_ARRAY => with_deps(
            "Marker[] markers\n",
            &[
                (
                    "visualization_msgs/Marker",
                    "int32 ARROW=0\nint32 CUBE=1\nint32 SPHERE=2\nint32 CYLINDER=3\nint32 LINE_STRIP=4\nint32 LINE_LIST=5\nint32 CUBE_LIST=6\nint32 SPHERE_LIST=7\nint32 POINTS=8\nint32 TEXT_VIEW_FACING=9\nint32 MESH_RESOURCE=10\nint32 TRIANGLE_LIST=11\nint32 ADD=0\nint32 MODIFY=0\nint32 DELETE=2\nint32 DELETEALL=3\nstd_msgs/Header header\nstring ns\nint32 id\nint32 type\nint32 action\ngeometry_msgs/Pose pose\ngeometry_msgs/Vector3 scale\nstd_msgs/ColorRGBA color\nbuiltin_interfaces/Duration lifetime\nbool frame_locked\ngeometry_msgs/Point[] points\nstd_msgs/ColorRGBA[] colors\nstring text\nstring mesh_resource\nbool mesh_use_embedded_materials\n",
                ),
                std_header,
                time,
                (
                    "geometry_msgs/Pose",
                    "Point position\nQuaternion orientation\n",
                ),
                ("geometry_msgs/Point", "float64 x\nfloat64 y\nfloat64 z\n"),
                (
                    "geometry_msgs/Quaternion",
                    "float64 x 0\nfloat64 y 0\nfloat64 z 0\nfloat64 w 1\n",
                ),
                ("geometry_msgs/Vector3", "float64 x\nfloat64 y\nfloat64 z\n"),
                (
                    "std_msgs/ColorRGBA",
                    "float32 r\nfloat32 g\nfloat32 b\nfloat32 a\n",
                ),
                ("builtin_interfaces/Duration", TIME),
            ],
        ),
        _ => return None,
    })
}
