"""The paper's maps, installed as the package pegame.maps_data."""
