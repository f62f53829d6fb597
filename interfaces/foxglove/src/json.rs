//! JSON channels: a `json` message encoding with a `jsonschema` schema
//! derived from a sample record, so a viewer knows the fields and types.

use serde_json::{Map, Value, json};

/// The JSON schema of records shaped like `sample`: an object whose
/// properties have the sample's types (arrays typed by their first item).
pub fn schema_of(title: &str, sample: &Value) -> Value {
    let mut schema = type_of(sample);
    if let Value::Object(o) = &mut schema {
        o.insert("title".into(), Value::String(title.to_string()));
        o.insert(
            "$schema".into(),
            Value::String("https://json-schema.org/draft/2020-12/schema".into()),
        );
    }
    schema
}

fn type_of(v: &Value) -> Value {
    match v {
        Value::Null => json!({}),
        Value::Bool(_) => json!({"type": "boolean"}),
        Value::Number(n) if n.is_f64() => json!({"type": "number"}),
        Value::Number(_) => json!({"type": "integer"}),
        Value::String(_) => json!({"type": "string"}),
        Value::Array(items) => match items.first() {
            Some(first) => json!({"type": "array", "items": type_of(first)}),
            None => json!({"type": "array"}),
        },
        Value::Object(fields) => {
            let properties: Map<String, Value> = fields
                .iter()
                .map(|(k, v)| (k.clone(), type_of(v)))
                .collect();
            json!({"type": "object", "properties": properties})
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_schema_follows_the_sample() {
        let s = schema_of(
            "x.Rec",
            &json!({"a": 1, "b": 0.5, "c": "s", "d": [1.0, 2.0], "e": true, "f": null}),
        );
        assert_eq!(s["title"], "x.Rec");
        assert_eq!(s["type"], "object");
        let p = &s["properties"];
        assert_eq!(p["a"]["type"], "integer");
        assert_eq!(p["b"]["type"], "number");
        assert_eq!(p["c"]["type"], "string");
        assert_eq!(p["d"]["items"]["type"], "number");
        assert_eq!(p["e"]["type"], "boolean");
        assert_eq!(p["f"], json!({}));
    }
}
