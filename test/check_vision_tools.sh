#!/bin/sh
# The offline tools write the documented CSV headers and rows: bag_detect_legs on a real bag, detect_people on a
# the first two frames of vtest.avi and on a folder of images (file names in the frame column); bad arguments exit with status 2.
# usage: check_vision_tools.sh BAG_DETECT_LEGS DETECT_PEOPLE PACKAGE_DIR TEST_DATA
set -e
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
"$1" --bag "$4/leg_tracker/positive_4_extracted.bag" --topic /training_scan \
  --model "$3/config/leg_classifier.yml" --out "$tmp/legs.csv"
[ "$(head -1 "$tmp/legs.csv")" = "stamp,x,y,confidence" ] || { echo "bad legs header"; exit 1; }
rows=$(($(wc -l < "$tmp/legs.csv") - 1))
[ "$rows" -gt 100 ] || { echo "too few legs: $rows"; exit 1; }
mkdir "$tmp/images"
cp /usr/share/doc/opencv-doc/examples/data/basketball1.png /usr/share/doc/opencv-doc/examples/data/baboon.jpg "$tmp/images/"
echo "not an image" > "$tmp/images/notes.txt"
"$2" --images "$tmp/images" --out "$tmp/images.csv" >/dev/null
[ "$(head -1 "$tmp/images.csv")" = "frame,x,y,width,height,confidence" ] || { echo "bad images header"; exit 1; }
# Every row names one of the two image files.
if tail -n +2 "$tmp/images.csv" | cut -d, -f1 | grep -v -x -e basketball1.png -e baboon.jpg | grep -q .; then
  echo "bad frame names"; exit 1
fi
"$2" --video /usr/share/doc/opencv-doc/examples/data/vtest.avi --out "$tmp/video.csv" --resize 1.5 --max-frames 2 >/dev/null
[ "$(head -1 "$tmp/video.csv")" = "frame,x,y,width,height,confidence" ] || { echo "bad people header"; exit 1; }
[ "$(sed -n 2p "$tmp/video.csv" | cut -d, -f1)" = "0" ] || { echo "first video row is not frame 0"; exit 1; }
# The recall vs false-legs curve of the labelled and the no-people recording: header and the seven thresholds.
D="$4/leg_tracker"
"$1" --curve --labelled "$D/positive_4_extracted.bag" --negatives "$D/negative_2.bag" --negatives-from 0.9 \
  --model "$3/config/leg_classifier.yml" > "$tmp/curve.md"
grep -q "^| setting | leg_threshold | leg recall | precision | false legs / scan" "$tmp/curve.md" || { echo "no curve header"; cat "$tmp/curve.md"; exit 1; }
[ "$(grep -c '^| min_cluster_points 3, all beams | 0\.[2-8] |' "$tmp/curve.md")" -eq 7 ] || { echo "curve rows"; cat "$tmp/curve.md"; exit 1; }
# Scored against the hand labels: the table header and one row for the labelled frames among the first 200.
"$2" --video /usr/share/doc/opencv-doc/examples/data/vtest.avi --labels "$3/test/data/vtest_people.csv" \
  --max-frames 3 > "$tmp/score.md"
grep -q "^| option | min_confidence | recall | precision" "$tmp/score.md" || { echo "no score table"; cat "$tmp/score.md"; exit 1; }
grep -q "^| default, resize 1.50, scale 1.10" "$tmp/score.md" || { echo "no score row"; cat "$tmp/score.md"; exit 1; }
set +e
"$1" --bag /nonexistent.bag >/dev/null 2>&1; [ $? -eq 2 ] || { echo "usage error not 2"; exit 1; }
"$1" --curve --negatives /nonexistent.bag >/dev/null 2>&1; [ $? -eq 2 ] || { echo "curve without labels not 2"; exit 1; }
"$2" --images "$tmp/images" >/dev/null 2>&1; [ $? -eq 2 ] || { echo "usage error not 2"; exit 1; }
"$2" --images "$tmp/images" --sweep >/dev/null 2>&1; [ $? -eq 2 ] || { echo "sweep without labels not 2"; exit 1; }
echo "vision tools ok ($rows legs)"
