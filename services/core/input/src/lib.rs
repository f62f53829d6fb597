//! Recorded lidar frames in: PCD/PLY directories, MCAP files (Foxglove
//! `PointCloud`) and ROS 2 bags (`sensor_msgs/msg/PointCloud2`), each frame
//! with per-point times.
