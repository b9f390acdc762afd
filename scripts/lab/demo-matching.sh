# Sourced by the demo-scene measurements (colmap4-mappers.sh, repair-loop.sh), from the
# repository's root: their common set-up, and one fresh matching of the demo's 20 rendered images
# into DIR/full.db, by COLMAP 3.8 or by pycolmap 4.2 (PY), 1024 SIFT features, the renderer's
# intrinsics given. SCENE, NUM_IMAGES and SEED (default duplicate, 20, 1: the demo) render
# another design instead, to judge on scenes the measurements were not tuned on.
# usage: demo_setup WORK                 (sets bin, PY, images and num_images)
#        match_demo MATCHER IMAGES DIR   (MATCHER: colmap3.8 | pycolmap4.2)

# The binary (VGSEL, else target/release/vgsel-colmap, built if missing) as bin, pycolmap's python
# (scripts/ci/pycolmap-venv.sh) as PY, and WORK emptied with the scene rendered into WORK/scene
# (its images: images; their number: num_images).
demo_setup() {
  local work=$1
  bin=${VGSEL:-target/release/vgsel-colmap}
  [ -x "$bin" ] || cargo build --release --quiet
  PY=$(bash scripts/ci/pycolmap-venv.sh)
  rm -rf "$work"
  mkdir -p "$work"
  num_images=${NUM_IMAGES:-20}
  "$bin" generate images --scene "${SCENE:-duplicate}" --num_images "$num_images" \
    --seed "${SEED:-1}" --output "$work/scene" -q
  images=$work/scene/images
}

match_demo() {
  local matcher=$1 images=$2 dir=$3 params=400,240,180,0
  if [ "$matcher" = colmap3.8 ]; then
    nice colmap feature_extractor --database_path "$dir/full.db" --image_path "$images" \
      --ImageReader.camera_model SIMPLE_RADIAL --ImageReader.single_camera 1 \
      --ImageReader.camera_params "$params" --SiftExtraction.use_gpu 0 \
      --SiftExtraction.max_num_features 1024 >"$dir/extract.log" 2>&1
    nice colmap exhaustive_matcher --database_path "$dir/full.db" --SiftMatching.use_gpu 0 \
      >"$dir/match.log" 2>&1
  else
    nice "$PY" scripts/ci/colmap4.py database "$images" "$dir/full.db" --camera_params "$params" \
      >"$dir/match.log" 2>&1
  fi
}
