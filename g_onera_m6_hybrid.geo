Merge "/work/main/build/tests/config_runs/out/onera_m6_hybrid/onera_m6_hybrid.msh";
Plugin(AnalyseMeshQuality).JacobianDeterminant=1;
Plugin(AnalyseMeshQuality).DimensionOfElements=3;
Plugin(AnalyseMeshQuality).Recompute=1;
Plugin(AnalyseMeshQuality).Run;
