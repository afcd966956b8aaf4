"""The paper's maps and a TurtleBot3 SLAM map, shipped as the package pegame.maps."""
