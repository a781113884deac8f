# The STOP record moves from the live app to cobots: its table stays where it is
# (live_cellstop); only Django's state of which app owns it changes.

import django.db.models.deletion
from django.conf import settings
from django.db import migrations, models


class Migration(migrations.Migration):

    dependencies = [
        ('cobots', '0007_cell_help'),
        ('live', '0001_initial'),
        ('organisations', '0002_alter_membership_membership_one_per_user_and_organisation_and_more'),
        migrations.swappable_dependency(settings.AUTH_USER_MODEL),
    ]

    operations = [
        migrations.SeparateDatabaseAndState(
            state_operations=[
                migrations.CreateModel(
                    name='CellStop',
                    fields=[
                        ('id', models.BigAutoField(auto_created=True, primary_key=True, serialize=False, verbose_name='ID')),
                        ('cell', models.CharField(blank=True, help_text='Empty: the whole floor.', max_length=50)),
                        ('stopped_at', models.DateTimeField(auto_now_add=True)),
                        ('resumed_at', models.DateTimeField(blank=True, null=True)),
                        ('cobots', models.JSONField(default=list, help_text='The ids of the cobots it paused.')),
                        ('problems', models.JSONField(blank=True, default=dict, help_text='Cobot id → why it could not be paused or resumed.')),
                        ('organisation', models.ForeignKey(on_delete=django.db.models.deletion.CASCADE, related_name='cell_stops', to='organisations.organisation')),
                        ('resumed_by', models.ForeignKey(blank=True, null=True, on_delete=django.db.models.deletion.SET_NULL, related_name='+', to=settings.AUTH_USER_MODEL)),
                        ('stopped_by', models.ForeignKey(null=True, on_delete=django.db.models.deletion.SET_NULL, related_name='+', to=settings.AUTH_USER_MODEL)),
                    ],
                    options={
                        'db_table': 'live_cellstop',
                        'ordering': ['-stopped_at', '-id'],
                        'constraints': [models.UniqueConstraint(condition=models.Q(('resumed_at__isnull', True)), fields=('organisation', 'cell'), name='cell_stop_one_active_per_cell')],
                    },
                ),
            ],
            database_operations=[],
        ),
        migrations.AlterField(
            model_name='cobot',
            name='stopped_at',
            field=models.DateTimeField(blank=True, editable=False, help_text="Set while a tablet's STOP holds the cobot paused (hrc.cobots.stops); no job starts.", null=True),
        ),
    ]
