//! The robot's frames as the agent learns them: map→odom from `/tf` or a map pose topic, the
//! robot's own frames from `/tf` and `/tf_static` (the latter asked from its publishers'
//! caches, as rmw_zenoh serves a transient-local topic), and where the scanner sits on the
//! base. Untrusted transforms stay bounded ([`MAX_FRAMES`], [`MAX_FRAME_DEPTH`]).

use super::{Latest, RosCounters, SCAN_POSE_TOLERANCE_S, log_now, rotate};
use crate::math::{Real, Vec2};
use ros2_wire::decode;
use ros2_wire::msg::{PoseWithCovarianceStamped, TFMessage};
use std::collections::{BTreeMap, VecDeque};
use std::sync::atomic::Ordering;
use std::sync::{Arc, Mutex, Weak};
use std::time::Duration;

/// The robot's own frames kept from `/tf` and `/tf_static` (untrusted input stays bounded).
pub(super) const MAX_FRAMES: usize = 64;
/// The longest chain of frames from the scanner to the base.
const MAX_FRAME_DEPTH: usize = 8;
/// How often `/tf_static`'s publishers are asked for their history until one answers.
const TF_STATIC_RETRY: Duration = Duration::from_secs(2);

/// The odometry pose (position, yaw in the odometry frame) nearest `at`, if one is within
/// [`SCAN_POSE_TOLERANCE_S`] of it.
pub(super) fn pose_at(poses: &VecDeque<(Real, Vec2, Real)>, at: Real) -> Option<(Vec2, Real)> {
    poses
        .iter()
        .min_by(|a, b| (a.0 - at).abs().total_cmp(&(b.0 - at).abs()))
        .filter(|(t, ..)| (t - at).abs() <= SCAN_POSE_TOLERANCE_S)
        .map(|&(_, position, yaw)| (position, yaw))
}

/// Where `frame` sits in `base` (offset, yaw), following parents through `frames`; `None`
/// when the chain does not reach `base` within [`MAX_FRAME_DEPTH`] links.
pub(super) fn mount_of(
    frames: &BTreeMap<String, (String, Vec2, Real)>,
    frame: &str,
    base: &str,
) -> Option<(Vec2, Real)> {
    let (mut offset, mut yaw) = (Vec2::zeros(), 0.0);
    let mut at = frame;
    for _ in 0..MAX_FRAME_DEPTH {
        if at == base {
            return Some((offset, yaw));
        }
        let (parent, t, r) = frames.get(at)?;
        offset = t + rotate(offset, *r);
        yaw += r;
        at = parent;
    }
    None
}

/// Takes a transform message: map→odom (when `map_from_tf`) from a transform out of the map
/// frame, and every other into the robot's frames, which stay within [`MAX_FRAMES`].
pub(super) fn take_transforms(
    l: &mut Latest,
    m: &TFMessage,
    map_frame: &str,
    map_from_tf: bool,
    c: &RosCounters,
) {
    for t in &m.transforms {
        let parent = t.header.frame_id.trim_start_matches('/');
        let child = t.child_frame_id.trim_start_matches('/');
        let tr = &t.transform;
        let pose = (
            Vec2::new(tr.translation.x, tr.translation.y),
            tr.rotation.yaw(),
        );
        if parent == map_frame {
            if map_from_tf {
                c.tf.fetch_add(1, Ordering::Relaxed);
                l.map_from_odom = Some(pose);
            }
        } else if !child.is_empty()
            && child != parent
            && (l.frames.contains_key(child) || l.frames.len() < MAX_FRAMES)
        {
            c.tf.fetch_add(1, Ordering::Relaxed);
            l.frames
                .insert(child.to_owned(), (parent.to_owned(), pose.0, pose.1));
        }
    }
}

/// Takes a map pose (AMCL's, say): map→odom is the pose composed with the inverse of the
/// odometry pose at its stamp. A pose in another frame, or with no odometry near its stamp,
/// is refused and counted.
pub(super) fn take_map_pose(
    l: &mut Latest,
    m: &PoseWithCovarianceStamped,
    map_frame: &str,
    c: &RosCounters,
) {
    let pose = &m.pose.pose;
    let matched = (m.header.frame_id.trim_start_matches('/') == map_frame)
        .then(|| pose_at(&l.poses, m.header.stamp.as_secs()))
        .flatten();
    let Some((odom_position, odom_yaw)) = matched else {
        let n = c.rejected.fetch_add(1, Ordering::Relaxed) + 1;
        if log_now(n) {
            tracing::warn!(
                frame = %m.header.frame_id,
                rejected = n,
                "map pose refused: not in the map frame, or no odometry near its stamp"
            );
        }
        return;
    };
    c.poses.fetch_add(1, Ordering::Relaxed);
    let yaw = pose.orientation.yaw() - odom_yaw;
    let offset = Vec2::new(pose.position.x, pose.position.y) - rotate(odom_position, yaw);
    l.map_from_odom = Some((offset, yaw));
}

/// Asks `/tf_static`'s publishers for their cached transforms (`history`, the topic's
/// `@adv` key), every [`TF_STATIC_RETRY`] until a static transform has come, by either way;
/// ends when the link is gone.
pub(super) async fn ask_static_history(
    session: zenoh::Session,
    history: String,
    latest: Weak<Mutex<Latest>>,
    counters: Arc<RosCounters>,
    map_frame: String,
    map_from_tf: bool,
) {
    loop {
        let Some(strong) = latest.upgrade() else {
            return;
        };
        if strong.lock().unwrap_or_else(|e| e.into_inner()).static_seen {
            return;
        }
        drop(strong);
        let replies = session
            .get(&history)
            .accept_replies(zenoh::query::ReplyKeyExpr::Any)
            .consolidation(zenoh::query::ConsolidationMode::None)
            .target(zenoh::query::QueryTarget::All)
            .timeout(TF_STATIC_RETRY)
            .await;
        if let Ok(replies) = replies {
            while let Ok(reply) = replies.recv_async().await {
                let Ok(sample) = reply.into_result() else {
                    continue;
                };
                let Some(strong) = latest.upgrade() else {
                    return;
                };
                match decode::<TFMessage>(&sample.payload().to_bytes()) {
                    Ok(m) => {
                        let mut l = strong.lock().unwrap_or_else(|e| e.into_inner());
                        l.static_seen = true;
                        take_transforms(&mut l, &m, &map_frame, map_from_tf, &counters);
                    }
                    Err(e) => {
                        let n = counters.rejected.fetch_add(1, Ordering::Relaxed) + 1;
                        if log_now(n) {
                            tracing::warn!(rejected = n, "bad cached /tf_static refused: {e}");
                        }
                    }
                }
            }
        }
        tokio::time::sleep(TF_STATIC_RETRY).await;
    }
}
