namespace emaki::exemplar {}
