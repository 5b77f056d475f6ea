//! What a BVH joint's name says it is, across the common naming conventions: CMU
//! (`LeftUpLeg`, `LHipJoint`), Mixamo (`mixamorig:LeftUpLeg`), 3ds Max biped
//! (`Bip01 L Thigh`) and generic names (`thigh_L`, `Thigh.L`, `L_Thigh`, `lThigh`,
//! `LeftThigh`, any case).
//!
//! A name is split into words (at separators and lower-to-upper case changes); a leading or
//! trailing `Left`/`Right`/`L`/`R` word gives the side, and the rest, joined and lowercased,
//! is looked up among the synonyms of each part of the body.

/// A side of the body.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Side {
    /// The body's left (garnet's +X).
    Left,
    /// The body's right.
    Right,
}

/// A bone of one side of the body, in chain order from the trunk.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Limb {
    /// CMU's pelvic hip bone (`lhipjoint`), from the pelvis to the hip joint.
    HipJoint,
    /// Thigh.
    UpLeg,
    /// Shin.
    Leg,
    /// Foot.
    Foot,
    /// Toes.
    Toe,
    /// Clavicle.
    Shoulder,
    /// Upper arm.
    Arm,
    /// Forearm.
    ForeArm,
    /// Hand.
    Hand,
}

/// The part of the body a joint's name names.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Role {
    /// The pelvis (`Hips`, `Pelvis`, `hip`, `root`).
    Hips,
    /// One joint of the spine between pelvis and neck (`Spine2`, `Chest`, `abdomen`).
    Spine,
    /// One joint of the neck.
    Neck,
    /// The head.
    Head,
    /// A bone of one side.
    Limb(Side, Limb),
    /// A thumb joint.
    Thumb(Side),
    /// A joint of another finger; the number ranks which finger stands for the hand's
    /// fingers (0: index, then unnamed, middle, ring, little).
    Finger(Side, u8),
}

/// Synonyms of each limb bone (lowercase, words joined, trailing digits removed).
const LIMBS: [(Limb, &[&str]); 9] = [
    (Limb::HipJoint, &["hipjoint"]),
    (
        Limb::UpLeg,
        &["upleg", "thigh", "upperleg", "legupper", "hip", "femur"],
    ),
    (
        Limb::Leg,
        &[
            "leg", "shin", "calf", "knee", "lowerleg", "leglower", "tibia",
        ],
    ),
    (Limb::Foot, &["foot", "ankle"]),
    (Limb::Toe, &["toebase", "toe", "toes", "ball"]),
    (
        Limb::Shoulder,
        &["shoulder", "clavicle", "collar", "collarbone"],
    ),
    (
        Limb::Arm,
        &["arm", "upperarm", "armupper", "shldr", "humerus"],
    ),
    (
        Limb::ForeArm,
        &["forearm", "lowerarm", "armlower", "elbow", "radius"],
    ),
    (Limb::Hand, &["hand", "wrist"]),
];

const SPINE: [&str; 14] = [
    "spine",
    "chest",
    "upperchest",
    "chestupper",
    "chestlower",
    "abdomen",
    "abdomenupper",
    "abdomenlower",
    "torso",
    "back",
    "lowerback",
    "upperback",
    "thorax",
    "waist",
];

const NECK: [&str; 5] = ["neck", "lowerneck", "upperneck", "neckupper", "necklower"];

/// Words that mark a joint as the end of a chain, not a bone (`HeadTop_End`, `Toe0Nub`).
const END_WORDS: [&str; 4] = ["end", "nub", "tip", "top"];

/// Fingers by rank (see [`Role::Finger`]).
const FINGERS: [&str; 6] = ["index", "finger", "middle", "ring", "pinky", "little"];

/// What `name` names, or `None` for a joint the conventions do not place (an end joint,
/// a 3ds Max `Bip01` root, a prop).
pub fn role(name: &str) -> Option<Role> {
    let name = name.rsplit([':', '|']).next().unwrap_or(name);
    let mut words = split_words(name);
    let biped = words
        .first()
        .is_some_and(|w| w.starts_with("bip") && w[3..].chars().all(|c| c.is_ascii_digit()));
    if biped {
        words.remove(0);
    }
    if words
        .iter()
        .any(|w| END_WORDS.contains(&w.trim_end_matches(digit)))
    {
        return None;
    }
    let side_of = |w: Option<&String>| match w.map(String::as_str) {
        Some("left" | "l") => Some(Side::Left),
        Some("right" | "r") => Some(Side::Right),
        _ => None,
    };
    let mut side = None;
    if words.len() > 1 {
        if let Some(s) = side_of(words.first()) {
            side = Some(s);
            words.remove(0);
        } else if let Some(s) = side_of(words.last()) {
            side = Some(s);
            words.pop();
        }
    }
    let base: String = words.concat();
    if let Some(r) = classify(&base, side, biped) {
        return Some(r);
    }
    // Lowercase names with the side glued on: `leftupleg`, `lthigh`, `handright`.
    let glued = [
        ("left", Side::Left),
        ("right", Side::Right),
        ("l", Side::Left),
        ("r", Side::Right),
    ];
    if side.is_none() {
        for (p, s) in glued {
            let rest = base.strip_prefix(p).or_else(|| base.strip_suffix(p));
            if let Some(r) = rest.and_then(|rest| classify(rest, Some(s), biped)) {
                return Some(r);
            }
        }
    }
    None
}

fn digit(c: char) -> bool {
    c.is_ascii_digit()
}

/// The role of a name's base (side removed); sided parts need a side.
fn classify(base: &str, side: Option<Side>, biped: bool) -> Option<Role> {
    let plain = base.trim_end_matches(digit);
    match (plain, side) {
        ("hips" | "hip" | "pelvis" | "root", None) => return Some(Role::Hips),
        ("head", None) => return Some(Role::Head),
        (p, None) if SPINE.contains(&p) => return Some(Role::Spine),
        (p, None) if NECK.contains(&p) => return Some(Role::Neck),
        _ => {}
    }
    let side = side?;
    // The 3ds Max biped numbers its fingers from the thumb (`Finger0`, `Finger01`).
    if base.contains("thumb") || (biped && base.starts_with("finger0")) {
        return Some(Role::Thumb(side));
    }
    if let Some(rank) = FINGERS.iter().position(|f| base.contains(f)) {
        return Some(Role::Finger(side, rank as u8));
    }
    LIMBS
        .iter()
        .find(|(_, names)| names.contains(&plain))
        .map(|(limb, _)| Role::Limb(side, *limb))
}

/// Lowercase words of a name: split at non-alphanumeric characters, before an upper-case
/// letter that follows a lower-case letter or digit, and before the last capital of a run
/// of capitals followed by a lower-case letter (`LHipJoint` -> `l hip joint`).
fn split_words(name: &str) -> Vec<String> {
    let chars: Vec<char> = name.chars().collect();
    let mut words: Vec<String> = Vec::new();
    let mut cur = String::new();
    for (i, &c) in chars.iter().enumerate() {
        if !c.is_ascii_alphanumeric() {
            if !cur.is_empty() {
                words.push(std::mem::take(&mut cur));
            }
            continue;
        }
        let prev = i.checked_sub(1).map(|p| chars[p]);
        let next = chars.get(i + 1);
        let boundary = c.is_ascii_uppercase()
            && prev.is_some_and(|p| {
                p.is_ascii_lowercase()
                    || p.is_ascii_digit()
                    || (p.is_ascii_uppercase() && next.is_some_and(|n| n.is_ascii_lowercase()))
            });
        if boundary && !cur.is_empty() {
            words.push(std::mem::take(&mut cur));
        }
        cur.push(c.to_ascii_lowercase());
    }
    if !cur.is_empty() {
        words.push(cur);
    }
    words
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn conventions_name_the_same_parts() {
        use Limb::*;
        use Side::*;
        let cases: [(&str, Option<Role>); 34] = [
            ("Hips", Some(Role::Hips)),
            ("mixamorig:Hips", Some(Role::Hips)),
            ("Bip01 Pelvis", Some(Role::Hips)),
            ("Bip01", None),
            ("LHipJoint", Some(Role::Limb(Left, HipJoint))),
            ("LeftUpLeg", Some(Role::Limb(Left, UpLeg))),
            ("mixamorig:RightUpLeg", Some(Role::Limb(Right, UpLeg))),
            ("Bip01 L Thigh", Some(Role::Limb(Left, UpLeg))),
            ("Bip01_R_Calf", Some(Role::Limb(Right, Leg))),
            ("thigh_L", Some(Role::Limb(Left, UpLeg))),
            ("Shin.R", Some(Role::Limb(Right, Leg))),
            ("L_UpperArm", Some(Role::Limb(Left, Arm))),
            ("lShldr", Some(Role::Limb(Left, Arm))),
            ("rCollar", Some(Role::Limb(Right, Shoulder))),
            ("lefthand", Some(Role::Limb(Left, Hand))),
            ("lthigh", Some(Role::Limb(Left, UpLeg))),
            ("LeftForeArm", Some(Role::Limb(Left, ForeArm))),
            ("Bip01 L Forearm", Some(Role::Limb(Left, ForeArm))),
            ("LeftToeBase", Some(Role::Limb(Left, Toe))),
            ("Bip01 R Toe0", Some(Role::Limb(Right, Toe))),
            ("mixamorig:LeftToe_End", None),
            ("HeadTop_End", None),
            ("Bip01 HeadNub", None),
            ("mixamorig:Spine2", Some(Role::Spine)),
            ("LowerBack", Some(Role::Spine)),
            ("Chest", Some(Role::Spine)),
            ("Neck1", Some(Role::Neck)),
            ("Head", Some(Role::Head)),
            ("LThumb", Some(Role::Thumb(Left))),
            ("Bip01 L Finger0", Some(Role::Thumb(Left))),
            ("Bip01 L Finger1", Some(Role::Finger(Left, 1))),
            ("mixamorig:LeftHandIndex1", Some(Role::Finger(Left, 0))),
            ("LeftFingerBase", Some(Role::Finger(Left, 1))),
            ("Leg", None),
        ];
        for (name, want) in cases {
            assert_eq!(role(name), want, "{name}");
        }
    }
}
