//! A `field` axis's path and values, checked before any scene is read: a path of names and
//! list positions, not one an axis of its own sets, and values JSON holds as they are.

use serde_json::Value;

use crate::base::error::FieldError;

/// Scene fields a `field` axis may not set, and the axis that does: the run takes these from
/// its own settings, which would win over the scene's without a word.
const OWN_AXES: [(&str, &str); 5] = [
    ("dt", "dt"),
    ("solver", "solver"),
    ("spawn.seed", "seed"),
    ("spawn.area_fraction", "area_fraction"),
    ("spawn.count", "area_fraction"),
];

/// Checks a `field` axis (`field` names it in errors): a path of names and list positions
/// joined by dots, not one of [`OWN_AXES`], and values JSON can hold (finite numbers).
pub(super) fn check_axis(path: &str, values: &[ron::Value], field: &str) -> Result<(), FieldError> {
    let word = |w: &str| {
        let digits = w.bytes().all(|b| b.is_ascii_digit());
        !w.is_empty()
            && w.bytes().all(|b| b.is_ascii_alphanumeric() || b == b'_')
            && !(digits && w.len() > 1 && w.starts_with('0'))
    };
    if !path.split('.').all(word) {
        return Err(FieldError::new(
            field,
            format!(
                "{path:?} is not a field's path: names (or list positions) joined by dots, \
                 such as \"effects.restitution\""
            ),
        ));
    }
    if let Some((_, axis)) = OWN_AXES.iter().find(|(p, _)| *p == path) {
        return Err(FieldError::new(
            field,
            format!("{path:?} is set by the `{axis}` axis: sweep it with that"),
        ));
    }
    for (k, value) in values.iter().enumerate() {
        if let Some(bad) = non_finite(value) {
            return Err(FieldError::new(
                format!("{field}[{k}]"),
                format!("{bad} is not a number a scene takes"),
            ));
        }
        if let Err(e) = serde_json::to_value(value) {
            return Err(FieldError::new(format!("{field}[{k}]"), e.to_string()));
        }
    }
    Ok(())
}

/// The first number in `value` that is not finite (JSON, which a task's fields go through,
/// has none).
fn non_finite(value: &ron::Value) -> Option<f64> {
    match value {
        ron::Value::Number(n) => Some(n.into_f64()).filter(|x| !x.is_finite()),
        ron::Value::Option(Some(inner)) => non_finite(inner),
        ron::Value::Seq(items) => items.iter().find_map(non_finite),
        ron::Value::Map(map) => map
            .iter()
            .find_map(|(k, v)| non_finite(k).or(non_finite(v))),
        _ => None,
    }
}

/// A checked field value ([`check_axis`]) as JSON.
pub(super) fn json_of(value: &ron::Value) -> Value {
    serde_json::to_value(value).expect("a checked field value")
}
