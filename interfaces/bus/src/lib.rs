//! iceoryx2 and zenoh transport of the spacepose service suite.
