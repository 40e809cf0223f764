// No include guard: every back-end header and every shipped model header includes this file at its
// end, and each entry below takes effect once, as soon as its back-end and models are all declared,
// whatever the order of the includes.
//
/// \file Compiled mode (docs/build_times.md). A program that links sextant::compiled (CMake) gets
/// SEXTANT_COMPILED_INSTANCES defined: the back-ends of the shipped model pairs listed here are then
/// explicit instantiation declarations (extern template), compiled once in the library
/// (src/compiled/, one translation unit per pair) instead of in every translation unit that uses
/// them. The headers alone, without the define, instantiate everything themselves as before.
/// A pair added here needs its SEXTANT_DEFINE_INSTANCES line in src/compiled/ (the link fails
/// otherwise, naming the missing member).
#if defined(SEXTANT_COMPILED_INSTANCES)


// BeaconShip2D x BeaconOffset2D
#if defined(SEXTANT_DECLARED_EKF_SLAM) && defined(SEXTANT_DECLARED_BEACON_SHIP_2D) && !defined(SEXTANT_EXTERN_EKF_SLAM_SHIP)
#define SEXTANT_EXTERN_EKF_SLAM_SHIP
extern template class sextant::EkfSlam<sextant::BeaconShip2D, sextant::BeaconOffset2D>;
#endif
#if defined(SEXTANT_DECLARED_SEIF_SLAM) && defined(SEXTANT_DECLARED_BEACON_SHIP_2D) && !defined(SEXTANT_EXTERN_SEIF_SLAM_SHIP)
#define SEXTANT_EXTERN_SEIF_SLAM_SHIP
extern template class sextant::SeifSlam<sextant::BeaconShip2D, sextant::BeaconOffset2D>;
#endif
#if defined(SEXTANT_DECLARED_GRAPH_SLAM) && defined(SEXTANT_DECLARED_BEACON_SHIP_2D) && !defined(SEXTANT_EXTERN_GRAPH_SLAM_SHIP)
#define SEXTANT_EXTERN_GRAPH_SLAM_SHIP
extern template class sextant::GraphSlam<sextant::BeaconShip2D, sextant::BeaconOffset2D>;
#endif
#if defined(SEXTANT_DECLARED_FAST_SLAM) && defined(SEXTANT_DECLARED_BEACON_SHIP_2D) && !defined(SEXTANT_EXTERN_FAST_SLAM_SHIP)
#define SEXTANT_EXTERN_FAST_SLAM_SHIP
extern template class sextant::FastSlam<sextant::BeaconShip2D, sextant::BeaconOffset2D>;
#endif

// Se2Odometry x RangeBearing2D
#if defined(SEXTANT_DECLARED_EKF_SLAM) && defined(SEXTANT_DECLARED_SE2_ODOMETRY) && defined(SEXTANT_DECLARED_RANGE_BEARING_2D) && !defined(SEXTANT_EXTERN_EKF_SLAM_RAWLOG_2D)
#define SEXTANT_EXTERN_EKF_SLAM_RAWLOG_2D
extern template class sextant::EkfSlam<sextant::Se2Odometry, sextant::RangeBearing2D>;
#endif
#if defined(SEXTANT_DECLARED_SEIF_SLAM) && defined(SEXTANT_DECLARED_SE2_ODOMETRY) && defined(SEXTANT_DECLARED_RANGE_BEARING_2D) && !defined(SEXTANT_EXTERN_SEIF_SLAM_RAWLOG_2D)
#define SEXTANT_EXTERN_SEIF_SLAM_RAWLOG_2D
extern template class sextant::SeifSlam<sextant::Se2Odometry, sextant::RangeBearing2D>;
#endif
#if defined(SEXTANT_DECLARED_GRAPH_SLAM) && defined(SEXTANT_DECLARED_SE2_ODOMETRY) && defined(SEXTANT_DECLARED_RANGE_BEARING_2D) && !defined(SEXTANT_EXTERN_GRAPH_SLAM_RAWLOG_2D)
#define SEXTANT_EXTERN_GRAPH_SLAM_RAWLOG_2D
extern template class sextant::GraphSlam<sextant::Se2Odometry, sextant::RangeBearing2D>;
#endif
#if defined(SEXTANT_DECLARED_FAST_SLAM) && defined(SEXTANT_DECLARED_SE2_ODOMETRY) && defined(SEXTANT_DECLARED_RANGE_BEARING_2D) && !defined(SEXTANT_EXTERN_FAST_SLAM_RAWLOG_2D)
#define SEXTANT_EXTERN_FAST_SLAM_RAWLOG_2D
extern template class sextant::FastSlam<sextant::Se2Odometry, sextant::RangeBearing2D>;
#endif

// Se2Odometry x PointInRobotFrame2D
#if defined(SEXTANT_DECLARED_EKF_SLAM) && defined(SEXTANT_DECLARED_SE2_ODOMETRY) && defined(SEXTANT_DECLARED_POINT_IN_ROBOT_FRAME_2D) && !defined(SEXTANT_EXTERN_EKF_SLAM_ISAM_2D)
#define SEXTANT_EXTERN_EKF_SLAM_ISAM_2D
extern template class sextant::EkfSlam<sextant::Se2Odometry, sextant::PointInRobotFrame2D>;
#endif
#if defined(SEXTANT_DECLARED_SEIF_SLAM) && defined(SEXTANT_DECLARED_SE2_ODOMETRY) && defined(SEXTANT_DECLARED_POINT_IN_ROBOT_FRAME_2D) && !defined(SEXTANT_EXTERN_SEIF_SLAM_ISAM_2D)
#define SEXTANT_EXTERN_SEIF_SLAM_ISAM_2D
extern template class sextant::SeifSlam<sextant::Se2Odometry, sextant::PointInRobotFrame2D>;
#endif
#if defined(SEXTANT_DECLARED_GRAPH_SLAM) && defined(SEXTANT_DECLARED_SE2_ODOMETRY) && defined(SEXTANT_DECLARED_POINT_IN_ROBOT_FRAME_2D) && !defined(SEXTANT_EXTERN_GRAPH_SLAM_ISAM_2D)
#define SEXTANT_EXTERN_GRAPH_SLAM_ISAM_2D
extern template class sextant::GraphSlam<sextant::Se2Odometry, sextant::PointInRobotFrame2D>;
#endif
#if defined(SEXTANT_DECLARED_FAST_SLAM) && defined(SEXTANT_DECLARED_SE2_ODOMETRY) && defined(SEXTANT_DECLARED_POINT_IN_ROBOT_FRAME_2D) && !defined(SEXTANT_EXTERN_FAST_SLAM_ISAM_2D)
#define SEXTANT_EXTERN_FAST_SLAM_ISAM_2D
extern template class sextant::FastSlam<sextant::Se2Odometry, sextant::PointInRobotFrame2D>;
#endif

// InWorldFrame<Se2Odometry> x SeenInWorldFrame<PointInRobotFrame2D>
#if defined(SEXTANT_DECLARED_EKF_SLAM) && defined(SEXTANT_DECLARED_SE2_ODOMETRY) && defined(SEXTANT_DECLARED_POINT_IN_ROBOT_FRAME_2D) && defined(SEXTANT_DECLARED_SE2_WORLD_FRAME) && !defined(SEXTANT_EXTERN_EKF_SLAM_ISAM_2D_WORLD)
#define SEXTANT_EXTERN_EKF_SLAM_ISAM_2D_WORLD
extern template class sextant::EkfSlam<sextant::InWorldFrame<sextant::Se2Odometry>, sextant::SeenInWorldFrame<sextant::PointInRobotFrame2D>>;
#endif
#if defined(SEXTANT_DECLARED_SEIF_SLAM) && defined(SEXTANT_DECLARED_SE2_ODOMETRY) && defined(SEXTANT_DECLARED_POINT_IN_ROBOT_FRAME_2D) && defined(SEXTANT_DECLARED_SE2_WORLD_FRAME) && !defined(SEXTANT_EXTERN_SEIF_SLAM_ISAM_2D_WORLD)
#define SEXTANT_EXTERN_SEIF_SLAM_ISAM_2D_WORLD
extern template class sextant::SeifSlam<sextant::InWorldFrame<sextant::Se2Odometry>, sextant::SeenInWorldFrame<sextant::PointInRobotFrame2D>>;
#endif
#if defined(SEXTANT_DECLARED_GRAPH_SLAM) && defined(SEXTANT_DECLARED_SE2_ODOMETRY) && defined(SEXTANT_DECLARED_POINT_IN_ROBOT_FRAME_2D) && defined(SEXTANT_DECLARED_SE2_WORLD_FRAME) && !defined(SEXTANT_EXTERN_GRAPH_SLAM_ISAM_2D_WORLD)
#define SEXTANT_EXTERN_GRAPH_SLAM_ISAM_2D_WORLD
extern template class sextant::GraphSlam<sextant::InWorldFrame<sextant::Se2Odometry>, sextant::SeenInWorldFrame<sextant::PointInRobotFrame2D>>;
#endif
#if defined(SEXTANT_DECLARED_FAST_SLAM) && defined(SEXTANT_DECLARED_SE2_ODOMETRY) && defined(SEXTANT_DECLARED_POINT_IN_ROBOT_FRAME_2D) && defined(SEXTANT_DECLARED_SE2_WORLD_FRAME) && !defined(SEXTANT_EXTERN_FAST_SLAM_ISAM_2D_WORLD)
#define SEXTANT_EXTERN_FAST_SLAM_ISAM_2D_WORLD
extern template class sextant::FastSlam<sextant::InWorldFrame<sextant::Se2Odometry>, sextant::SeenInWorldFrame<sextant::PointInRobotFrame2D>>;
#endif

// Se3Odometry x RangeBearing3D
#if defined(SEXTANT_DECLARED_EKF_SLAM) && defined(SEXTANT_DECLARED_SE3_ODOMETRY) && defined(SEXTANT_DECLARED_RANGE_BEARING_3D) && !defined(SEXTANT_EXTERN_EKF_SLAM_RAWLOG_3D)
#define SEXTANT_EXTERN_EKF_SLAM_RAWLOG_3D
extern template class sextant::EkfSlam<sextant::Se3Odometry, sextant::RangeBearing3D>;
#endif
#if defined(SEXTANT_DECLARED_SEIF_SLAM) && defined(SEXTANT_DECLARED_SE3_ODOMETRY) && defined(SEXTANT_DECLARED_RANGE_BEARING_3D) && !defined(SEXTANT_EXTERN_SEIF_SLAM_RAWLOG_3D)
#define SEXTANT_EXTERN_SEIF_SLAM_RAWLOG_3D
extern template class sextant::SeifSlam<sextant::Se3Odometry, sextant::RangeBearing3D>;
#endif
#if defined(SEXTANT_DECLARED_GRAPH_SLAM) && defined(SEXTANT_DECLARED_SE3_ODOMETRY) && defined(SEXTANT_DECLARED_RANGE_BEARING_3D) && !defined(SEXTANT_EXTERN_GRAPH_SLAM_RAWLOG_3D)
#define SEXTANT_EXTERN_GRAPH_SLAM_RAWLOG_3D
extern template class sextant::GraphSlam<sextant::Se3Odometry, sextant::RangeBearing3D>;
#endif
#if defined(SEXTANT_DECLARED_FAST_SLAM) && defined(SEXTANT_DECLARED_SE3_ODOMETRY) && defined(SEXTANT_DECLARED_RANGE_BEARING_3D) && !defined(SEXTANT_EXTERN_FAST_SLAM_RAWLOG_3D)
#define SEXTANT_EXTERN_FAST_SLAM_RAWLOG_3D
extern template class sextant::FastSlam<sextant::Se3Odometry, sextant::RangeBearing3D>;
#endif

// Unicycle x RangeBearing2D
#if defined(SEXTANT_DECLARED_EKF_SLAM) && defined(SEXTANT_DECLARED_UNICYCLE) && defined(SEXTANT_DECLARED_RANGE_BEARING_2D) && !defined(SEXTANT_EXTERN_EKF_SLAM_MRCLAM)
#define SEXTANT_EXTERN_EKF_SLAM_MRCLAM
extern template class sextant::EkfSlam<sextant::Unicycle, sextant::RangeBearing2D>;
#endif
#if defined(SEXTANT_DECLARED_SEIF_SLAM) && defined(SEXTANT_DECLARED_UNICYCLE) && defined(SEXTANT_DECLARED_RANGE_BEARING_2D) && !defined(SEXTANT_EXTERN_SEIF_SLAM_MRCLAM)
#define SEXTANT_EXTERN_SEIF_SLAM_MRCLAM
extern template class sextant::SeifSlam<sextant::Unicycle, sextant::RangeBearing2D>;
#endif
#if defined(SEXTANT_DECLARED_GRAPH_SLAM) && defined(SEXTANT_DECLARED_UNICYCLE) && defined(SEXTANT_DECLARED_RANGE_BEARING_2D) && !defined(SEXTANT_EXTERN_GRAPH_SLAM_MRCLAM)
#define SEXTANT_EXTERN_GRAPH_SLAM_MRCLAM
extern template class sextant::GraphSlam<sextant::Unicycle, sextant::RangeBearing2D>;
#endif
#if defined(SEXTANT_DECLARED_FAST_SLAM) && defined(SEXTANT_DECLARED_UNICYCLE) && defined(SEXTANT_DECLARED_RANGE_BEARING_2D) && !defined(SEXTANT_EXTERN_FAST_SLAM_MRCLAM)
#define SEXTANT_EXTERN_FAST_SLAM_MRCLAM
extern template class sextant::FastSlam<sextant::Unicycle, sextant::RangeBearing2D>;
#endif

// InWorldFrame<Unicycle> x SeenInWorldFrame<RangeBearing2D>
#if defined(SEXTANT_DECLARED_EKF_SLAM) && defined(SEXTANT_DECLARED_UNICYCLE) && defined(SEXTANT_DECLARED_RANGE_BEARING_2D) && defined(SEXTANT_DECLARED_SE2_WORLD_FRAME) && !defined(SEXTANT_EXTERN_EKF_SLAM_MRCLAM_WORLD)
#define SEXTANT_EXTERN_EKF_SLAM_MRCLAM_WORLD
extern template class sextant::EkfSlam<sextant::InWorldFrame<sextant::Unicycle>, sextant::SeenInWorldFrame<sextant::RangeBearing2D>>;
#endif
#if defined(SEXTANT_DECLARED_SEIF_SLAM) && defined(SEXTANT_DECLARED_UNICYCLE) && defined(SEXTANT_DECLARED_RANGE_BEARING_2D) && defined(SEXTANT_DECLARED_SE2_WORLD_FRAME) && !defined(SEXTANT_EXTERN_SEIF_SLAM_MRCLAM_WORLD)
#define SEXTANT_EXTERN_SEIF_SLAM_MRCLAM_WORLD
extern template class sextant::SeifSlam<sextant::InWorldFrame<sextant::Unicycle>, sextant::SeenInWorldFrame<sextant::RangeBearing2D>>;
#endif
#if defined(SEXTANT_DECLARED_GRAPH_SLAM) && defined(SEXTANT_DECLARED_UNICYCLE) && defined(SEXTANT_DECLARED_RANGE_BEARING_2D) && defined(SEXTANT_DECLARED_SE2_WORLD_FRAME) && !defined(SEXTANT_EXTERN_GRAPH_SLAM_MRCLAM_WORLD)
#define SEXTANT_EXTERN_GRAPH_SLAM_MRCLAM_WORLD
extern template class sextant::GraphSlam<sextant::InWorldFrame<sextant::Unicycle>, sextant::SeenInWorldFrame<sextant::RangeBearing2D>>;
#endif
#if defined(SEXTANT_DECLARED_FAST_SLAM) && defined(SEXTANT_DECLARED_UNICYCLE) && defined(SEXTANT_DECLARED_RANGE_BEARING_2D) && defined(SEXTANT_DECLARED_SE2_WORLD_FRAME) && !defined(SEXTANT_EXTERN_FAST_SLAM_MRCLAM_WORLD)
#define SEXTANT_EXTERN_FAST_SLAM_MRCLAM_WORLD
extern template class sextant::FastSlam<sextant::InWorldFrame<sextant::Unicycle>, sextant::SeenInWorldFrame<sextant::RangeBearing2D>>;
#endif

// EulerCamera12D x PointInCamera3D
#if defined(SEXTANT_DECLARED_EKF_SLAM) && defined(SEXTANT_DECLARED_EULER_CAMERA_12D) && !defined(SEXTANT_EXTERN_EKF_SLAM_GLOBE)
#define SEXTANT_EXTERN_EKF_SLAM_GLOBE
extern template class sextant::EkfSlam<sextant::EulerCamera12D, sextant::PointInCamera3D>;
#endif
#if defined(SEXTANT_DECLARED_SEIF_SLAM) && defined(SEXTANT_DECLARED_EULER_CAMERA_12D) && !defined(SEXTANT_EXTERN_SEIF_SLAM_GLOBE)
#define SEXTANT_EXTERN_SEIF_SLAM_GLOBE
extern template class sextant::SeifSlam<sextant::EulerCamera12D, sextant::PointInCamera3D>;
#endif
#if defined(SEXTANT_DECLARED_GRAPH_SLAM) && defined(SEXTANT_DECLARED_EULER_CAMERA_12D) && !defined(SEXTANT_EXTERN_GRAPH_SLAM_GLOBE)
#define SEXTANT_EXTERN_GRAPH_SLAM_GLOBE
extern template class sextant::GraphSlam<sextant::EulerCamera12D, sextant::PointInCamera3D>;
#endif
#if defined(SEXTANT_DECLARED_FAST_SLAM) && defined(SEXTANT_DECLARED_EULER_CAMERA_12D) && !defined(SEXTANT_EXTERN_FAST_SLAM_GLOBE)
#define SEXTANT_EXTERN_FAST_SLAM_GLOBE
extern template class sextant::FastSlam<sextant::EulerCamera12D, sextant::PointInCamera3D>;
#endif

// ImuVelocitySe3 x StereoPixelsSe3
#if defined(SEXTANT_DECLARED_EKF_SLAM) && defined(SEXTANT_DECLARED_STEREO_IMU_SE3) && !defined(SEXTANT_EXTERN_EKF_SLAM_STEREO_VI)
#define SEXTANT_EXTERN_EKF_SLAM_STEREO_VI
extern template class sextant::EkfSlam<sextant::ImuVelocitySe3, sextant::StereoPixelsSe3>;
#endif
#if defined(SEXTANT_DECLARED_SEIF_SLAM) && defined(SEXTANT_DECLARED_STEREO_IMU_SE3) && !defined(SEXTANT_EXTERN_SEIF_SLAM_STEREO_VI)
#define SEXTANT_EXTERN_SEIF_SLAM_STEREO_VI
extern template class sextant::SeifSlam<sextant::ImuVelocitySe3, sextant::StereoPixelsSe3>;
#endif
#if defined(SEXTANT_DECLARED_GRAPH_SLAM) && defined(SEXTANT_DECLARED_STEREO_IMU_SE3) && !defined(SEXTANT_EXTERN_GRAPH_SLAM_STEREO_VI)
#define SEXTANT_EXTERN_GRAPH_SLAM_STEREO_VI
extern template class sextant::GraphSlam<sextant::ImuVelocitySe3, sextant::StereoPixelsSe3>;
#endif
#if defined(SEXTANT_DECLARED_FAST_SLAM) && defined(SEXTANT_DECLARED_STEREO_IMU_SE3) && !defined(SEXTANT_EXTERN_FAST_SLAM_STEREO_VI)
#define SEXTANT_EXTERN_FAST_SLAM_STEREO_VI
extern template class sextant::FastSlam<sextant::ImuVelocitySe3, sextant::StereoPixelsSe3>;
#endif

#endif  // SEXTANT_COMPILED_INSTANCES
