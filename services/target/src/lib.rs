//! Target spacecraft models: meshes, built-in targets, materials, symmetries, surface sampling and BVH ray casting
#![forbid(unsafe_code)]
